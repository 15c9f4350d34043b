"""mlc: the mechanical logic compiler.

Boolean logic in; gate netlists of slab-hinge-muscle mechanisms (Agrawal & Glotzer,
"Muscle-inspired flexible mechanical logic architecture for colloidal robotics"),
their 3D scenes, Brownian-dynamics verification and printable meshes out.
Units everywhere: sigma = 1 (muscle rest length), k0 = 1 (bond stiffness), gamma = 1 (drag).

Importing mlc before numpy defaults OpenBLAS to one thread (``OPENBLAS_NUM_THREADS``,
unless already set): mlc's dense linear algebra is on small matrices, where BLAS
threads only add overhead -- on a busy 2-core machine a 53x42 SVD took 48 ms threaded
against 0.3 ms on one thread.  The integrator and the mesher thread on their own.

It also pins OpenBLAS's kernels to its Haswell ones (``OPENBLAS_CORETYPE``, unless already
set, on x86-64 CPUs with AVX2 and FMA): the router's inverse kinematics (an SVD per
trust-region step) amplifies last-bit differences between kernels, so the same netlist
routed with OpenBLAS's SkylakeX kernels built a different full adder (4012 bodies against
3988 with Haswell's; docs/circuits.md, "Reproducibility").  With the pin, every such
machine builds the same circuit, the one mlc's committed results were verified on.

On CPUs with AVX-512 it also turns off numpy's AVX-512 code paths (``NPY_DISABLE_CPU_FEATURES``,
unless already set): there numpy computes float64 sin, cos, arcsin, arctan2 and others with its
own SIMD routines instead of the C library's, and their last bits differ.  The same router
amplifies those too: the full adder built with these five functions one ulp off on some elements
had 4012 bodies instead of 3948 (``benchmarks/build_ulp_sensitivity.py``).  Without AVX-512 numpy
computes them with the C library, the same bits as :mod:`math`.

It makes Numba prefer OpenMP to TBB for its parallel kernels (``NUMBA_THREADING_LAYER_PRIORITY``
"omp tbb workqueue", unless the user set it or ``NUMBA_THREADING_LAYER``), in every process that
imports mlc, not only those that load the integrator (:mod:`mlc.sim.kernels` made this choice
alone before session 46).  With TBB on the machine (Debian's libtbb12 comes with PrusaSlicer),
``mlc stl`` of the Tetris circuit ran its wall check's parallel kernel under TBB from worker
threads, wrote every file, and then never exited: the interpreter's exit hung in Numba's
``unload_tbb`` -> ``tbb::finalize``, spinning on ``sched_yield`` (a known Numba and oneTBB
problem with parallel code run from threads other than the main one: numba issue 10556).

When neither mlc's folder nor the user's cache directory is writable (a read-only install run
by a user without a writable home), it points Numba's kernel cache at a private temporary
directory (:mod:`mlc.io.numba_cache`), which Numba would otherwise refuse with "cannot cache".
"""
import os as _os
import sys as _sys


def _cpu_flags() -> set[str]:
    """The CPU's feature flags from /proc/cpuinfo on x86-64 Linux (empty elsewhere)."""
    import platform
    if platform.machine().lower() not in ("x86_64", "amd64"):
        return set()
    try:
        with open("/proc/cpuinfo") as f:
            for line in f:
                if line.startswith("flags"):
                    return set(line.split(":", 1)[1].split())
    except OSError:
        pass
    return set()


def _avx2_fma() -> bool:
    """True on an x86-64 Linux CPU that lists the avx2 and fma flags (OpenBLAS's Haswell kernels run there)."""
    flags = _cpu_flags()
    return "avx2" in flags and "fma" in flags


def _numpy_avx512_targets(version: str) -> str | None:
    """The names of numpy ``version``'s AVX-512 dispatch targets, as NPY_DISABLE_CPU_FEATURES takes
    them (a name numpy does not dispatch draws an ImportWarning), or None for a numpy mlc does not know."""
    try:
        major, minor = (int(x) for x in version.split(".")[:2])
    except ValueError:
        return None
    if (major, minor) >= (2, 4):  # dispatch targets regrouped by x86-64 level
        return "X86_V4 AVX512_ICL AVX512_SPR"
    if (major, minor) < (1, 26):
        return None
    names = "AVX512F AVX512CD AVX512_KNL AVX512_KNM AVX512_SKX AVX512_CLX AVX512_CNL AVX512_ICL"
    return names + " AVX512_SPR" if (major, minor) >= (2, 3) else names


def _pin_numpy_dispatch() -> None:
    """Set NPY_DISABLE_CPU_FEATURES to numpy's AVX-512 targets on a CPU with AVX-512 (see above)."""
    if "NPY_DISABLE_CPU_FEATURES" in _os.environ or "avx512f" not in _cpu_flags():
        return
    from importlib import metadata
    try:
        names = _numpy_avx512_targets(metadata.version("numpy"))
    except metadata.PackageNotFoundError:
        return
    if names:
        _os.environ["NPY_DISABLE_CPU_FEATURES"] = names


if "numpy" not in _sys.modules:
    _os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
    if "OPENBLAS_CORETYPE" not in _os.environ and _avx2_fma():
        _os.environ["OPENBLAS_CORETYPE"] = "Haswell"
    _pin_numpy_dispatch()

__version__ = "0.1.0"

from mlc.io.numba_cache import ensure as _ensure_numba_cache  # noqa: E402  (before Numba is loaded)

_ensure_numba_cache()

#: Numba's threading layers in mlc's order of preference (see the module docstring)
THREADING_LAYERS = ("omp", "tbb", "workqueue")
if "NUMBA_THREADING_LAYER" not in _os.environ and "NUMBA_THREADING_LAYER_PRIORITY" not in _os.environ:
    _os.environ["NUMBA_THREADING_LAYER_PRIORITY"] = " ".join(THREADING_LAYERS)   # read when Numba loads
    if "numba" in _sys.modules:                  # Numba already loaded: its configuration directly
        _sys.modules["numba"].config.THREADING_LAYER_PRIORITY = list(THREADING_LAYERS)
