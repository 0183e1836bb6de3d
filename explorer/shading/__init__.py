"""The engine: from a scene and a mesh to per-vertex colours.

Owns the plan (:mod:`.plan`: what a scene calls for, and why), the compiled kernels
(:mod:`.kernels`), the cached :class:`~.shader.Shader` and :func:`~.shader.shade`, the
lighting equation term by term in plain numpy (:mod:`.equation`: the specification the kernels
are tested against), the effects (:mod:`.effects`, :mod:`.shadows`) and the display pipeline
(:mod:`.display`: linear sums to 8-bit colours).

May import: :mod:`explorer.core`, :mod:`explorer.geometry`, numpy and numba. Never VTK, PyVista
or a GUI toolkit: ``import explorer`` loads this package.
"""
