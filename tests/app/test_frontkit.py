"""What both front ends share, tested once in the toolkit-free kit (:mod:`explorer.app`): the
start's light, ..."""

from __future__ import annotations

import numpy as np
import pytest

from explorer.app import start
from explorer.app.model import DEFAULT_PLACEMENT
from explorer.geometry.meshes import Mesh, get_mesh


def test_the_start_light_is_a_point_light_at_the_default_placement_in_mesh_radii():
    unit = get_mesh("sphere", 8)
    mesh = Mesh(unit.positions * 2.0 + (1.0, 0.0, 0.0), unit.normals, unit.faces)
    light = start.default_light(mesh)
    assert light.type == "point"
    az, el, d = light.placement(mesh.centre)
    assert (az, el) == pytest.approx(DEFAULT_PLACEMENT[:2])
    assert d == pytest.approx(DEFAULT_PLACEMENT[2] * mesh.radius)
    assert mesh.radius == pytest.approx(2.0 * unit.radius)
    assert np.allclose(mesh.centre, (1.0, 0.0, 0.0), atol=1e-9)
