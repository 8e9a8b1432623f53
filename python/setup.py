"""Builds the posedrop extension against the C library of this repository.

The extension links the static archives build/opt/libposedrop.a and
libposedrop-bullet.a, which `make` in the repository's root builds (this
script runs it), and the system's GSL, ODE, libccd and Bullet found by
pkg-config, the same libraries the posedrop command links. So the installed
module needs no LD_LIBRARY_PATH and computes with the very objects the
command runs.
"""
import os
import re
import shlex
import subprocess
import sys
from pathlib import Path

from setuptools import Extension, setup
from setuptools.command.build_ext import build_ext

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
BUILD = ROOT / "build" / "opt"
LIB_PKGS = ["gsl", "ode", "ccd", "bullet"]


def fail(message):
    sys.exit("posedrop: " + message)


def version():
    text = (ROOT / "include" / "posedrop" / "version.h").read_text()
    parts = [re.search(r"#define PD_VERSION_%s (\d+)" % k, text).group(1)
             for k in ("MAJOR", "MINOR", "PATCH")]
    return ".".join(parts)


def pkg_config(*args):
    try:
        out = subprocess.run(["pkg-config", *args], check=True, capture_output=True, text=True)
    except (OSError, subprocess.CalledProcessError) as e:
        fail("pkg-config %s failed (%s): install the dependencies with "
             "scripts/install-deps.sh" % (" ".join(args), e))
    return shlex.split(out.stdout)


class BuildWithLibrary(build_ext):
    """Runs make in the repository's root for the static archives first."""

    def run(self):
        if not (ROOT / "include" / "posedrop" / "posedrop.h").is_file():
            fail("%s is not a posedrop source tree: install with 'pip install ./python' "
                 "from the repository's root" % ROOT)
        make = os.environ.get("MAKE", "make")
        targets = ["build/opt/libposedrop.a", "build/opt/libposedrop-bullet.a"]
        jobs = os.environ.get("POSEDROP_MAKE_JOBS", "2")
        cmd = [make, "-C", str(ROOT), "-j" + jobs, *targets]
        print(" ".join(cmd))
        # The archives are built as plain `make` builds them: flags that
        # might be meant for the extension stay out of the library's build.
        env = {k: v for k, v in os.environ.items() if k not in ("CFLAGS", "LDFLAGS", "MAKEFLAGS")}
        if subprocess.call(cmd, env=env) != 0:
            fail("building the C library failed (%s)" % " ".join(cmd))
        ext = self.extensions[0]
        ext.include_dirs.append(str(ROOT / "include"))
        ext.extra_compile_args += [f for f in pkg_config("--cflags", "gsl", "ode", "ccd")
                                   if f.startswith("-I")]
        # The Bullet adapter first: it calls into libposedrop.
        ext.extra_objects += [str(BUILD / "libposedrop-bullet.a"), str(BUILD / "libposedrop.a")]
        libs = pkg_config("--libs", *LIB_PKGS)
        ext.extra_link_args += libs + ["-lstdc++", "-lm", "-pthread",
                                       # The library's functions stay inside the module.
                                       "-Wl,--exclude-libs,ALL"]
        super().run()


setup(
    version=version(),
    ext_modules=[Extension(
        "posedrop._posedrop",
        sources=["ext/posedrop_module.c"],
        extra_compile_args=["-std=c11", "-D_DEFAULT_SOURCE", "-Wall", "-Wextra",
                            "-Wno-missing-field-initializers", "-pthread",
                            "-ffp-contract=off"],
    )],
    cmdclass={"build_ext": BuildWithLibrary},
)
