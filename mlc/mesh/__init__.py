"""Printable meshes: scene -> parts (manifold3d CSG) -> STL/3MF, with a printability report.

The one call for other commands (``mlc stl``, ``mlc compile --stl``)::

    from mlc.mesh import export_scene
    report = export_scene(scene, "mjp", stl="x.stl", threemf="x.3mf")   # MlcError if a check fails

Modules: :mod:`~mlc.mesh.profiles` (printer profiles), :mod:`~mlc.mesh.build` (parts),
:mod:`~mlc.mesh.checks` (the report), :mod:`~mlc.mesh.pipeline` (many mechanisms, static
verification), :mod:`~mlc.mesh.export` (files), :mod:`~mlc.mesh.render` (pictures).
See docs/printing.md.
"""
from __future__ import annotations


def export_scene(scene, profile="mjp", *, stl=None, threemf=None, parts_dir=None, overrides=None, force=False,
           solve=True):
    """Build, check and (if the report passes, or ``force``) write the printable meshes of a scene.

    ``profile`` is a built-in name, a profile file or a :class:`~mlc.mesh.profiles.Profile`.
    Returns the :class:`~mlc.mesh.checks.Report` (``report.outputs`` lists the files written);
    raises :class:`~mlc.errors.MlcError` when a check fails and ``force`` is not set (nothing is
    written then)."""
    from mlc.errors import MlcError
    from mlc.mesh.export import part_meshes, write_outputs
    from mlc.mesh.pipeline import export_assembly
    from mlc.mesh.profiles import Profile, load_profile

    prof = profile if isinstance(profile, Profile) else load_profile(profile, overrides)
    asm, report = export_assembly(scene, prof, solve=solve)
    if report.ok or force:
        if stl or threemf or parts_dir:
            report.outputs = write_outputs(asm, stl=stl, threemf=threemf, parts_dir=parts_dir,
                                           meshes=part_meshes(asm))
    elif not force:
        failed = [c.name for c in report.checks if not c.ok and c.blocking]
        err = MlcError(f"printability checks failed: {', '.join(failed)}; nothing written", scene.source or scene.name,
                       "see the report, change the profile, or force the export")
        err.report = report
        raise err
    return report
