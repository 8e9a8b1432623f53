"""Ctrl-C, cancelling, and threads: the GIL is released during drops, a
SIGINT cancels the run cleanly, and results never depend on threads."""
import os
import signal
import threading

import numpy as np
import pytest

import posedrop
from conftest import PARTS

LONG = 100000  # about a minute of drops: only a cancel ends such a run in a test


@pytest.fixture(scope="module")
def cap():
    return posedrop.Part.from_file(PARTS / "cap.off")


def test_sigint_raises_keyboard_interrupt(cap):
    started = threading.Event()
    timer = threading.Thread(target=lambda: (started.wait(), os.kill(os.getpid(), signal.SIGINT)))
    timer.start()
    with pytest.raises(KeyboardInterrupt):
        cap.drop(LONG, threads=2, progress=lambda done, total: started.set())
    timer.join()
    # The module is usable afterwards, and the next run is whole.
    d = cap.drop(20, threads=2)
    assert d.n == 20 and not d.partial


def test_sigint_stops_drops_on_another_thread(cap):
    """Ctrl-C in the main thread stops drops a worker thread waits for: they
    ran on for a minute, the worker's Python code out of the signal's reach."""
    started, outcome = threading.Event(), []

    def work():
        try:
            cap.drop(LONG, threads=1, progress=lambda done, total: started.set())
            outcome.append("finished")
        except KeyboardInterrupt:
            outcome.append("interrupted")
    worker = threading.Thread(target=work)
    worker.start()
    started.wait()
    with pytest.raises(KeyboardInterrupt):
        os.kill(os.getpid(), signal.SIGINT)
        threading.Event().wait(60)  # the handler's KeyboardInterrupt ends it
    worker.join(60)
    assert not worker.is_alive() and outcome == ["interrupted"]


def test_cancel_without_is_set_refused_at_once(cap):
    with pytest.raises(TypeError, match="is_set"):
        cap.drop(LONG, cancel=5)


def test_cancel_event_returns_the_first_drops(cap):
    cancel = threading.Event()
    drops = cap.drop(LONG, threads=2, cancel=cancel,
                     progress=lambda done, total: done >= 30 and cancel.set())
    assert drops.partial and 30 <= drops.n < LONG
    # Each drop is the drop it would be in a full run: the first n drops.
    whole = cap.drop(drops.n, threads=1)
    assert not whole.partial
    assert np.array_equal(drops.count, whole.count) and drops.unsettled == whole.unsettled


def test_exception_in_progress_cancels_and_propagates(cap):
    def progress(done, total):
        raise RuntimeError("stop here")
    with pytest.raises(RuntimeError, match="stop here"):
        cap.drop(LONG, threads=2, progress=progress)


def test_threads_never_change_results(cap):
    one = cap.drop(120, seed=5, threads=1, trials=True)
    two = cap.drop(120, seed=5, threads=2, trials=True)
    every = cap.drop(120, seed=5, trials=True)
    for d in (two, every):
        assert np.array_equal(one.count, d.count)
        assert np.array_equal(one.trials.q0, d.trials.q0)
        assert np.array_equal(one.trials.pose, d.trials.pose)


def test_python_threads_drop_at_once_on_one_part(cap):
    """Two Python threads drop on the same part at the same time (the GIL is
    released) and each gets the run it would get alone."""
    alone = {seed: cap.drop(80, seed=seed, threads=1) for seed in (1, 2)}
    results = {}

    def run(seed):
        results[seed] = cap.drop(80, seed=seed, threads=1)
    threads = [threading.Thread(target=run, args=(s,)) for s in (1, 2)]
    for t in threads:
        t.start()
    # The main thread runs Python while the drops run.
    ticks = 0
    while any(t.is_alive() for t in threads):
        ticks += 1
        threads[0].join(0.001)
    for t in threads:
        t.join()
    assert ticks > 1
    for seed in (1, 2):
        assert np.array_equal(results[seed].count, alone[seed].count)


def test_parts_built_on_many_threads_agree():
    """Part builds and static estimates run without the GIL, four at once."""
    v = np.asarray(posedrop.Part.from_file(PARTS / "cap.off").vertices)
    f = np.asarray(posedrop.Part.from_file(PARTS / "cap.off").faces)
    out = [None] * 4

    def build(i):
        out[i] = posedrop.Part(v, f).stable_poses().p_qs
    ts = [threading.Thread(target=build, args=(i,)) for i in range(4)]
    for t in ts:
        t.start()
    for t in ts:
        t.join()
    assert all(np.array_equal(out[0], o) for o in out)


def test_ctrl_c_stops_a_python_process(tmp_path):
    """A SIGINT from outside, as a terminal's Ctrl-C sends it, while a
    script is in a long run: the script dies of KeyboardInterrupt, as any
    Python script does, and does not print a result."""
    import subprocess
    import sys
    script = tmp_path / "long.py"
    script.write_text(
        "import sys, posedrop\n"
        "part = posedrop.Part.from_file(%r)\n"
        "def progress(done, total):\n"
        "    print('running', flush=True)\n"
        "drops = part.drop(%d, threads=2, progress=progress)\n"
        "print('finished', drops.n)\n" % (str(PARTS / "cap.off"), LONG))
    child = subprocess.Popen([sys.executable, str(script)], stdout=subprocess.PIPE,
                             stderr=subprocess.PIPE, text=True)
    assert child.stdout.readline() == "running\n"
    child.send_signal(signal.SIGINT)
    out, err = child.communicate(timeout=300)
    assert "finished" not in out and "KeyboardInterrupt" in err
    # Python (3.8 on) ends an uncaught KeyboardInterrupt by SIGINT itself.
    assert child.returncode == -signal.SIGINT
