"""The scene IR: rigid slabs, bonds between body-fixed sites, muscles and probes.

This is the one description of a mechanism that every back end uses: the static
verifier, the Brownian-dynamics integrator and the mesh builder.  See
docs/scene-format.md for the on-disk form.
"""
from mlc.scene.model import Body, Bond, Box, Muscle, Probe, Scene, SceneArrays
from mlc.scene.io import dump_scene, load_scene, parse_scene, scene_to_data, write_scene

__all__ = ["Body", "Bond", "Box", "Muscle", "Probe", "Scene", "SceneArrays",
           "dump_scene", "load_scene", "parse_scene", "scene_to_data", "write_scene"]
