"""An off-screen :class:`~explorer.app.view.SceneView`, the shared view of both front ends,
for the tests that read its pixels without a window."""

from __future__ import annotations


def sphere_view(preset: str, size, background=(0.1, 0.1, 0.1)):
    """The explorer's start (``gui --mesh sphere --preset PRESET``) drawn in an off-screen
    plotter of ``size`` (w, h); the caller closes ``view.plotter``."""
    from explorer.app.view import SceneView
    from explorer.cli import build_parser
    from explorer.cli.gui import start_state
    from explorer.render.vtk import plotter

    state, mesh = start_state(
        build_parser().parse_args(["gui", "--mesh", "sphere", "--preset", preset])
    )
    return SceneView(plotter(size, background), mesh, state)
