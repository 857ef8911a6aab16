"""One BLAS thread per process unless the user chose a count (impstab._blas)."""

from __future__ import annotations

import os
import subprocess
import sys

import pytest

from impstab._blas import THREAD_VARIABLES, prefer_single_thread

_SHOW = """
import os, sys
from impstab.cli import main
main(["--version"])
print(os.environ.get("OPENBLAS_NUM_THREADS"), os.environ.get("MKL_NUM_THREADS"), "numpy" in sys.modules)
"""


def test_nothing_set_gives_one_thread():
    env: dict[str, str] = {}
    assert prefer_single_thread(env) is True
    assert env == {"OPENBLAS_NUM_THREADS": "1", "MKL_NUM_THREADS": "1"}


@pytest.mark.parametrize("name", THREAD_VARIABLES)
def test_a_users_choice_is_kept(name):
    env = {name: "4"}
    assert prefer_single_thread(env) is False
    assert env == {name: "4"}


def _show(**set_: str) -> list[str]:
    env = {k: v for k, v in os.environ.items() if k not in THREAD_VARIABLES}
    env.update(set_)
    done = subprocess.run([sys.executable, "-c", _SHOW], capture_output=True, text=True, env=env, timeout=120)
    assert done.returncode == 0, done.stderr
    return done.stdout.split()[-3:]


def test_the_command_line_sets_one_thread_before_numpy_loads():
    assert _show() == ["1", "1", "False"]


def test_the_command_line_keeps_the_users_thread_count():
    assert _show(OMP_NUM_THREADS="2") == ["None", "None", "False"]
