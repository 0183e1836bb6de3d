"""The model: what a scene is, read and written safely.

Owns errors and validation (:mod:`.errors`, :mod:`.validate`), safe YAML (:mod:`.yamlio`),
atomic files (:mod:`.atomic`), the material, lights, viewer and scene (:mod:`.material`,
:mod:`.lights`, :mod:`.scene`, :mod:`.hdr`), the row of light parameters the kernels read
(:mod:`.lightrow`: plain constants, so a light packs its own row), the preset library
(:mod:`.presets`) and every epsilon (:mod:`.tolerances`).

May import: the standard library, numpy, PyYAML and platformdirs. Nothing else of the package:
core knows nothing of geometry, shading, pictures or windows.
"""
