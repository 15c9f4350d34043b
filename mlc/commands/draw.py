"""``mlc draw``: render a gate or scene in its input states, or a mesh file."""
from __future__ import annotations

from pathlib import Path


MAX_STATES = 64             # panels of one picture (examples/mux4.blif's circuit has 6 inputs)


def register(sub):
    p = sub.add_parser("draw", help="render a gate or scene in every input state (PNG), or a mesh with --mesh",
                       description="Draw a library gate (by name) or a scene file in each of its input states, "
                                   "one panel per state, or with --mesh an STL/3MF file.  Lengths in sigma.")
    p.add_argument("target", nargs="?", help="library gate name or scene YAML file (not with --mesh)")
    p.add_argument("--signal", choices=("expand", "contract"), default="expand")
    p.add_argument("--mesh", metavar="STL", help="render this mesh file (.stl or .3mf) instead of a gate or scene")
    p.add_argument("-o", "--output", required=True, metavar="PNG", help="picture to write (.png)")
    p.set_defaults(func=run)


def load_target(target: str, signal: str):
    """A library gate name or a scene file -> Scene."""
    from mlc.gates.library import gate_scene
    from mlc.io.yamlsrc import read_text
    from mlc.scene.io import parse_scene
    if target.lower().endswith((".yaml", ".yml")) or Path(target).exists():
        return parse_scene(read_text(target, "scene"), str(target))
    return gate_scene(target, signal)


def run(args) -> int:
    from mlc.errors import MlcError
    from mlc.io.outputs import Outputs

    if args.mesh and args.target:
        raise MlcError(f"both a target ({args.target}) and --mesh given", "--mesh",
                       "draw either a gate/scene or a mesh file, not both")
    if not args.mesh and not args.target:
        raise MlcError("nothing to draw", "TARGET", "give a gate name, a scene file or --mesh FILE")
    source = args.mesh or args.target
    outs = Outputs(inputs=[source] if Path(source).exists() else [])
    png = outs.file(args.output, "-o", suffixes=(".png",))
    with outs:
        if args.mesh:
            from mlc.io.sniff import check_mesh_file
            from mlc.mesh.render import render_mesh
            check_mesh_file(args.mesh, max_triangles=400_000)
            render_mesh(args.mesh, png.tmp)
        else:
            from mlc.draw import draw_scene_states
            from mlc.io.progress import Progress
            from mlc.verify.static import equilibrium
            scene = load_target(args.target, args.signal)
            if 2 ** len(scene.inputs) > MAX_STATES:         # 8 inputs: 256 panels, 3 min, not legible
                raise MlcError(f"{len(scene.inputs)} inputs make {2 ** len(scene.inputs)} input states, more panels "
                               f"than one picture shows (at most {MAX_STATES}: 6 inputs)",
                               scene.source or scene.name, "mlc verify SCENE prints every row as a table")
            states = scene.states()
            # a compiled circuit takes minutes (1328 bodies: about 3 min); a gate about a second
            with Progress(f"mlc draw: solving and drawing {scene.name}", total=len(states) + 1) as bar:
                equilibria = {}
                for k, st in enumerate(states):         # mlc.verify.static.solve_states, one state at a time
                    equilibria[st] = equilibrium(scene, st, levels="depth")   # a circuit: as its static check
                    bar.update(k + 1)
                draw_scene_states(scene, equilibria, png.tmp)
                bar.update(len(states) + 1)
    print(f"wrote {args.output}")
    return 0
