"""mlc/__init__.py: importing mlc before numpy pins OpenBLAS's kernels (OPENBLAS_CORETYPE) so
that a circuit routes to the same bodies on every x86-64 CPU with AVX2 (the router's SVDs
amplify last-bit differences between kernels: docs/circuits.md, "Reproducibility")."""
import os
import subprocess
import sys

import pytest

import mlc

SVD = ("import hashlib, numpy as np; r = np.random.default_rng(3); A = r.standard_normal((53, 42)); "
       "u, s, vt = np.linalg.svd(A); "
       "print(hashlib.sha256(np.concatenate([u.ravel(), s, vt.ravel()]).tobytes()).hexdigest())")
avx2 = pytest.mark.skipif(not mlc._avx2_fma(), reason="the pin applies to x86-64 CPUs with AVX2 and FMA")


def _run(code: str, **env_set) -> str:
    env = {k: v for k, v in os.environ.items() if k != "OPENBLAS_CORETYPE"}
    env.update(env_set)
    return subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True,
                          check=True).stdout.strip()


@avx2
def test_pinned_before_numpy():
    assert _run("import mlc, os; print(os.environ.get('OPENBLAS_CORETYPE'))") == "Haswell"


@avx2
def test_svd_bits_are_haswell_s():
    # with the pin, an SVD after `import mlc` has the bits of OpenBLAS's Haswell kernels,
    # whatever kernel OpenBLAS would pick for this CPU on its own
    assert _run("import mlc\n" + SVD) == _run(SVD, OPENBLAS_CORETYPE="Haswell")


def test_user_choice_kept():
    assert _run("import mlc, os; print(os.environ['OPENBLAS_CORETYPE'])",
                OPENBLAS_CORETYPE="Sandybridge") == "Sandybridge"


def test_no_pin_once_numpy_is_loaded():
    # too late to take effect: mlc leaves the environment as it is
    assert _run("import numpy, mlc, os; print(os.environ.get('OPENBLAS_CORETYPE'))") == "None"
