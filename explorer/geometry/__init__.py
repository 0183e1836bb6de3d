"""Meshes and rays: the built-in meshes, mesh files, normals, the normalised frame the engine
shades in, and ray-triangle queries.

May import: :mod:`explorer.core`, numpy, numba, and trimesh / VTK inside the functions that need
them (mesh files, level of detail).
"""
