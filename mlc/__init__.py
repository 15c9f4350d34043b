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
"""
import os as _os
import sys as _sys


def _avx2_fma() -> bool:
    """True on an x86-64 Linux CPU that lists the avx2 and fma flags (OpenBLAS's Haswell kernels run there)."""
    import platform
    if platform.machine().lower() not in ("x86_64", "amd64"):
        return False
    try:
        with open("/proc/cpuinfo") as f:
            for line in f:
                if line.startswith("flags"):
                    flags = line.split(":", 1)[1].split()
                    return "avx2" in flags and "fma" in flags
    except OSError:
        pass
    return False


if "numpy" not in _sys.modules:
    _os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
    if "OPENBLAS_CORETYPE" not in _os.environ and _avx2_fma():
        _os.environ["OPENBLAS_CORETYPE"] = "Haswell"

__version__ = "0.1.0"
