"""mlc: the mechanical logic compiler.

Boolean logic in; gate netlists of slab-hinge-muscle mechanisms (Agrawal & Glotzer,
"Muscle-inspired flexible mechanical logic architecture for colloidal robotics"),
their 3D scenes, Brownian-dynamics verification and printable meshes out.
Units everywhere: sigma = 1 (muscle rest length), k0 = 1 (bond stiffness), gamma = 1 (drag).

Importing mlc before numpy defaults OpenBLAS to one thread (``OPENBLAS_NUM_THREADS``,
unless already set): mlc's dense linear algebra is on small matrices, where BLAS
threads only add overhead -- on a busy 2-core machine a 53x42 SVD took 48 ms threaded
against 0.3 ms on one thread.  The integrator and the mesher thread on their own.
"""
import os as _os
import sys as _sys

if "numpy" not in _sys.modules:
    _os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

__version__ = "0.1.0"
