"""``mlc draw``: render a gate or scene in its input states, or a mesh file."""
from __future__ import annotations

from pathlib import Path


def register(sub):
    p = sub.add_parser("draw", help="render a gate or scene in every input state (PNG), or a mesh with --mesh")
    p.add_argument("target", nargs="?", help="library gate name or scene YAML file")
    p.add_argument("--signal", choices=("expand", "contract"), default="expand")
    p.add_argument("--mesh", metavar="STL", help="render this mesh file instead")
    p.add_argument("-o", "--output", required=True, metavar="PNG")
    p.set_defaults(func=run)


def load_target(target: str, signal: str):
    """A library gate name or a scene file -> Scene."""
    from mlc.gates.library import gate_scene
    from mlc.scene.io import load_scene
    if target.lower().endswith((".yaml", ".yml")) or Path(target).exists():
        return load_scene(target)
    return gate_scene(target, signal)


def run(args) -> int:
    from mlc.errors import MlcError
    if args.mesh:
        from mlc.mesh.render import render_mesh
        render_mesh(args.mesh, args.output)
        print(f"wrote {args.output}")
        return 0
    if not args.target:
        raise MlcError("nothing to draw", "TARGET", "give a gate name, a scene file or --mesh FILE")
    from mlc.draw import draw_scene_states
    from mlc.verify.static import solve_states
    scene = load_target(args.target, args.signal)
    draw_scene_states(scene, solve_states(scene), args.output)
    print(f"wrote {args.output}")
    return 0
