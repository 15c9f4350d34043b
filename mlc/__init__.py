"""mlc: the mechanical logic compiler.

Boolean logic in; gate netlists of slab-hinge-muscle mechanisms (Agrawal & Glotzer,
"Muscle-inspired flexible mechanical logic architecture for colloidal robotics"),
their 3D scenes, Brownian-dynamics verification and printable meshes out.
Units everywhere: sigma = 1 (muscle rest length), k0 = 1 (bond stiffness), gamma = 1 (drag).
"""
__version__ = "0.1.0"
