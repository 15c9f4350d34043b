"""mlc/__init__.py: importing mlc before numpy pins OpenBLAS's kernels (OPENBLAS_CORETYPE) so
that a circuit routes to the same bodies on every x86-64 CPU with AVX2 (the router's SVDs
amplify last-bit differences between kernels: docs/circuits.md, "Reproducibility"), and on CPUs
with AVX-512 turns off numpy's AVX-512 code paths (NPY_DISABLE_CPU_FEATURES), whose float64
sin, cos, arcsin, arctan2 differ from the C library's in the last bits.  It also puts Numba's
OpenMP threading layer before TBB in every process (with TBB, ``mlc stl`` hung at exit)."""
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


def _run_numba(code: str, **env_set) -> str:
    """``code`` in a fresh interpreter whose environment has no Numba threading-layer choice
    (this test's own ``import mlc`` put one in os.environ)."""
    env = {k: v for k, v in os.environ.items() if not k.startswith("NUMBA_THREADING_LAYER")}
    env.update(env_set)
    return subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True,
                          check=True).stdout.strip()


PRIORITY = "import numba; print(numba.config.THREADING_LAYER, ' '.join(numba.config.THREADING_LAYER_PRIORITY))"


def test_numba_prefers_openmp_in_a_process_without_the_integrator():
    # the mesher's parallel wall kernel alone: before session 46 only mlc.sim.kernels chose the
    # order, and `mlc stl` ran that kernel under TBB from worker threads, then hung at exit
    out = _run_numba("import sys, mlc.mesh.walls\n" + PRIORITY + "\nprint('mlc.sim.kernels' in sys.modules)")
    assert out.split("\n") == ["default omp tbb workqueue", "False"]


def test_numba_loaded_before_mlc_is_configured_too():
    assert _run_numba("import numba, mlc\n" + PRIORITY) == "default omp tbb workqueue"


def test_numba_user_choice_kept():
    assert _run_numba("import mlc\n" + PRIORITY, NUMBA_THREADING_LAYER="workqueue") == \
        "workqueue tbb omp workqueue"
    assert _run_numba("import mlc\n" + PRIORITY, NUMBA_THREADING_LAYER_PRIORITY="workqueue omp tbb") == \
        "default workqueue omp tbb"


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


def test_avx512_names_are_numpy_s_own():
    # the names mlc gives NPY_DISABLE_CPU_FEATURES for the installed numpy are all targets that
    # numpy dispatches: a name it does not know would draw an ImportWarning (an error here)
    from importlib import metadata
    try:
        from numpy._core._multiarray_umath import __cpu_dispatch__
    except ImportError:  # numpy 1.x
        from numpy.core._multiarray_umath import __cpu_dispatch__
    names = mlc._numpy_avx512_targets(metadata.version("numpy"))
    assert names and set(names.split()) <= set(__cpu_dispatch__)
    assert all("512" in n or n == "X86_V4" for n in names.split())
    env = {k: v for k, v in os.environ.items() if k != "NPY_DISABLE_CPU_FEATURES"}
    env["NPY_DISABLE_CPU_FEATURES"] = names
    r = subprocess.run([sys.executable, "-W", "error::ImportWarning", "-c", "import numpy"], env=env,
                       capture_output=True, text=True)
    assert r.returncode == 0, r.stderr


def test_avx512_names_by_numpy_version():
    assert mlc._numpy_avx512_targets("2.4.6") == "X86_V4 AVX512_ICL AVX512_SPR"
    assert "AVX512_SPR" in mlc._numpy_avx512_targets("2.3.5").split()
    assert "AVX512_SPR" not in mlc._numpy_avx512_targets("2.2.6").split()
    assert "AVX512_SKX" in mlc._numpy_avx512_targets("1.26.4").split()
    assert mlc._numpy_avx512_targets("1.25.0") is None and mlc._numpy_avx512_targets("dev") is None


@pytest.mark.parametrize("flags,user,expect", [
    ({"avx2", "fma", "avx512f"}, None, "names"),
    ({"avx2", "fma"}, None, None),              # no AVX-512: numpy already calls the C library
    ({"avx2", "fma", "avx512f"}, "AVX2", "AVX2"),  # a user's own setting is kept
])
def test_numpy_dispatch_pin(monkeypatch, flags, user, expect):
    from importlib import metadata
    monkeypatch.setattr(mlc, "_cpu_flags", lambda: flags)
    if user is None:
        monkeypatch.delenv("NPY_DISABLE_CPU_FEATURES", raising=False)
    else:
        monkeypatch.setenv("NPY_DISABLE_CPU_FEATURES", user)
    mlc._pin_numpy_dispatch()
    want = mlc._numpy_avx512_targets(metadata.version("numpy")) if expect == "names" else expect
    assert os.environ.get("NPY_DISABLE_CPU_FEATURES") == want
