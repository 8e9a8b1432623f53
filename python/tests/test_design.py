"""The binding's design and design sensitivities against the command's, on
the same part with the same options: the same numbers as printed."""
import subprocess

import numpy as np

import posedrop
from conftest import CLI, PARTS, g10, run_cli

CUBE = PARTS / "canonical" / "cube.off"


def test_design_static_same_as_command(tmp_path):
    target = tmp_path / "t.csv"
    target.write_text("nx,ny,nz,p\n0,0,1,0.3333333333\n0,0,-1,0.3333333333\n"
                      "1,0,0,0.0833333333\n-1,0,0,0.0833333333\n0,1,0,0.0833333333\n"
                      "0,-1,0,0.0833333333\n")
    rows, header, err = run_cli("design", "--vary", "scale_z=0.1:3", "--target", target, "-n", 0,
                                "--check", 0, "--out", tmp_path / "d.off", CUBE)
    part = posedrop.Part.from_file(CUBE)
    d = part.design([("scale", "z", 0.1, 3.0)],
                    target=[(0, 0, 1, 0.3333333333), (0, 0, -1, 0.3333333333),
                            (1, 0, 0, 0.0833333333), (-1, 0, 0, 0.0833333333),
                            (0, 1, 0, 0.0833333333), (0, -1, 0, 0.0833333333)],
                    n=0, check=0)
    col = header.index("p_pqs_after")
    assert [r[col] for r in rows] == [g10(x) for x in d.pqs_after]
    assert d.value[0] < 1.0 and not d.vanished.any()
    # The changed part is a Part of its own: its estimate is the design's.
    assert np.allclose(d.part.stable_poses().p_pqs.max(), 1 / 3, atol=1e-8)


def test_design_sensitivity_same_as_command(tmp_path):
    sens = tmp_path / "s.csv"
    # Only the CSV file: nothing on stdout.
    subprocess.run([str(CLI), "design", "--vary", "scale_z=0.5:2,com_x=-0.001:0.001",
                    "--sensitivity", str(sens), "--sensitivity-drops", "0", str(CUBE)],
                   check=True, capture_output=True)
    lines = sens.read_text().splitlines()
    header = lines[0].split(",")
    part = posedrop.Part.from_file(CUBE)
    s = part.stable_poses().design_sensitivity([("scale", "z", 0.5, 2.0),
                                                ("com", "x", -0.001, 0.001)])
    qs = header.index("d_p_qs")
    assert [l.split(",")[qs] for l in lines[1:]] == [g10(x) for x in s.d_qs]
    assert len(s) == 2 * len(part.stable_poses())
