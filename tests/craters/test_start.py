"""The commands' start (:mod:`craters.cli.start`): numpy's SIMD dispatch capped at AVX2
before numpy loads, so that a command writes the same bytes on any x86-64 CPU; and numba's
threads told to sleep soon after they run out of work (``import craters``)."""

from __future__ import annotations

import os
import platform
import subprocess
import sys

import pytest

import craters
from craters.cli.start import NUMPY_SIMD_CAP

CAP = ("import os; from craters.cli.start import cap_numpy_simd; got = cap_numpy_simd(); "
       "import numpy; print(repr(got)); print(repr(os.environ.get('NPY_DISABLE_CPU_FEATURES')))")


def _python(code: str, **env: str | None) -> list[str]:
    """The first two lines ``code`` prints in a new interpreter whose ImportWarnings are
    errors (numpy warns so of a feature name it does not know) and whose environment is
    this one's updated by ``env`` (None: unset)."""
    full = dict(os.environ)
    for key, value in env.items():
        full.pop(key, None)
        if value is not None:
            full[key] = value
    run = subprocess.run([sys.executable, "-W", "error::ImportWarning", "-c", code],
                         capture_output=True, text=True, env=full, timeout=120)
    assert run.returncode == 0, run.stderr
    return run.stdout.splitlines()[:2]


@pytest.mark.skipif(platform.machine().lower() not in ("x86_64", "amd64"),
                    reason="the cap names x86-64 features; elsewhere numpy is left as it is")
def test_numpy_is_capped_before_it_loads_with_names_this_numpy_knows():
    got, env = _python(CAP, NPY_DISABLE_CPU_FEATURES=None)
    assert got == env and eval(got) in NUMPY_SIMD_CAP.values()


@pytest.mark.parametrize("value", ["", "X86_V3"])
def test_a_users_own_setting_is_kept(value):
    assert _python(CAP, NPY_DISABLE_CPU_FEATURES=value) == ["None", repr(value)]


def test_nothing_is_changed_once_numpy_is_loaded():
    assert _python("import numpy; " + CAP, NPY_DISABLE_CPU_FEATURES=None) == ["None", "None"]


def test_an_unknown_feature_name_would_fail_the_check():
    """The control: the ImportWarning numpy gives for a name it does not know fails
    :func:`_python`, so the first test fails when numpy renames its levels."""
    with pytest.raises(AssertionError, match="ImportWarning"):
        _python("import numpy", NPY_DISABLE_CPU_FEATURES="NO_SUCH_FEATURE")


@pytest.mark.parametrize("given, want", [({}, craters.THREAD_SPIN_COUNT),
                                         ({"GOMP_SPINCOUNT": "50"}, "50"),
                                         ({"OMP_WAIT_POLICY": "active"}, "None")])
def test_numba_threads_spin_briefly_unless_the_environment_says(given, want):
    env = {"GOMP_SPINCOUNT": None, "OMP_WAIT_POLICY": None} | given
    code = "import os, latlong; print(os.environ.get('GOMP_SPINCOUNT')); print()"
    assert _python(code, **env)[0] == want
