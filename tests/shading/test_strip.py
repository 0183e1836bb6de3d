"""The term strip's numbers (explorer.shading.strip): the engine's own terms, recomposed."""

from __future__ import annotations

import numpy as np
import pytest
from helpers.scenes import random_gl_scene

from explorer.core.presets import find_preset
from explorer.core.scene import Scene, load_scene
from explorer.geometry.meshes import get_mesh
from explorer.shading.display import shown, to_bytes
from explorer.shading.shader import Shader, kept_sums, shade
from explorer.shading.strip import (
    TERMS,
    compose_strip,
    light_scene,
    shader_strip,
    shader_strip_bytes,
    term_colors,
)

#: the float terms add up to the rendered colour within this, per vertex and channel (issue 41)
SUM_TOLERANCE = 1e-12


def _scenes():
    """Scenes of every model, with effects and several lights of each type (seeded)."""
    rng = np.random.default_rng(41)
    out = []
    for i, model in enumerate(("blinn", "phong", "threejs", "blinn", "phong")):
        s = random_gl_scene(rng)
        s["model"] = model
        if i >= 3:  # the material's effects on the specular term
            s["material"].update(fresnel=0.3, energy_conserving=True)
        out.append(load_scene(s))
    out.append(Scene(material=find_preset("gold")))
    return out


@pytest.mark.parametrize(
    ("index", "tier"),
    [(i, t) for i in range(6) for t in ("compiled", "numpy") if (i, t) != (2, "compiled")],
)  # (scene 2 is threejs: the numpy tier computes it)
def test_the_float_terms_add_up_to_the_rendered_colour_per_vertex(index, tier):
    scene = _scenes()[index]
    mesh = get_mesh("teapot")
    P, N, F = mesh.positions, mesh.normals, mesh.faces
    colour = shade(scene, P, N, clamp=False, faces=F, tier=tier)  # the render's colours
    sh = Shader(scene, P, N, precision="float64", clamp=False, faces=F, tier=tier)
    strip = shader_strip(sh)
    t = strip.terms
    added = t["emission"] + t["ambient"] + t["diffuse"] + t["specular"]
    assert np.abs(added - colour).max() <= SUM_TOLERANCE
    assert np.abs(t["sum"] - colour).max() <= SUM_TOLERANCE
    assert colour.max() > 0.05  # (the scene lights the mesh: the check means something)


def test_raw_terms_are_the_light_sums_and_weighted_ones_the_coefficients_times_them():
    scene = _scenes()[0]
    mesh = get_mesh("sphere")
    sh = Shader(scene, mesh.positions, mesh.normals, precision="float64")
    sums = sh.terms
    raw, weighted = shader_strip(sh, "raw").terms, shader_strip(sh, "weighted").terms
    m = scene.material
    for name, k in (("ambient", m.ambient), ("diffuse", m.diffuse), ("specular", m.specular)):
        np.testing.assert_array_equal(raw[name], sums[name])
        np.testing.assert_allclose(weighted[name], np.asarray(k) * sums[name], rtol=0, atol=0)
    np.testing.assert_array_equal(raw["sum"], weighted["sum"])
    with pytest.raises(ValueError, match="strip mode must be one of"):
        term_colors(m, sums, "linear")


@pytest.mark.parametrize("hdr", [None, {"exposure": 1.0, "tone_map": "clamp"}])
def test_the_overflow_mask_is_set_exactly_where_clamping_changed_a_value(hdr):
    scene = Scene(material=find_preset("gold"), hdr=hdr)
    mesh = get_mesh("teapot")
    P, N = mesh.positions, mesh.normals
    raw = shade(scene, P, N, clamp=False)
    if hdr is None:
        changed = np.any(shade(scene, P, N, clamp=True) != raw, axis=1)
    else:  # the display's clamp after the exposure
        x = raw * 2.0
        changed = np.any(np.minimum(x, 1.0) != x, axis=1)
    sh = Shader(scene, P, N, precision="float64", clamp=hdr is None)
    strip = shader_strip(sh)
    assert 0 < changed.sum() < len(changed)  # gold's highlight saturates, the rest does not
    np.testing.assert_array_equal(strip.overflow, changed)
    # the 8-bit tiles add up to more than the sum tile somewhere there, never elsewhere
    if hdr is None:
        byte = {k: np.rint(np.clip(v, 0, 1) * 255) for k, v in strip.tiles.items()}
        parts = byte["emission"] + byte["ambient"] + byte["diffuse"] + byte["specular"]
        over = np.any(parts - byte["sum"] > 2, axis=1)  # (each tile rounds: up to 2 apart)
        assert over.any() and not over[~strip.overflow].any()


def test_the_sum_tile_is_the_display_of_the_engine_colours():
    scene = Scene(material=find_preset("jade"), hdr={"exposure": -0.5, "tone_map": "aces"})
    mesh = get_mesh("sphere")
    sh = Shader(scene, mesh.positions, mesh.normals, precision="float64", clamp=False)
    strip = shader_strip(sh)
    np.testing.assert_array_equal(strip.tiles["sum"], shown(sh.colors, scene))
    assert set(strip.tiles) == set(TERMS)
    assert not strip.overflow.any()  # (aces saturates only from 0.6·x = 7.25)


def test_the_strip_recomposes_the_cached_sums_without_a_light_pass():
    scene = Scene(material=find_preset("gold"))
    mesh = get_mesh("sphere")
    sh = Shader(scene, mesh.positions, mesh.normals, precision="float64")
    shader_strip(sh)
    passes = sh.stats["pass"] + sh.stats["numpy"]
    sh.set_material(scene.material.replace(diffuse=(0.1, 0.6, 0.3)))  # colours only: compose
    strip = shader_strip(sh, "raw")
    assert sh.stats["pass"] + sh.stats["numpy"] == passes
    clamped = np.clip(strip.terms["sum"], 0.0, 1.0)
    np.testing.assert_allclose(clamped, sh.colors, rtol=0, atol=SUM_TOLERANCE)


def test_a_light_row_is_what_that_light_adds():
    scene = _scenes()[1]
    mesh = get_mesh("sphere")
    P, N = mesh.positions, mesh.normals
    rows = [shade(light_scene(scene, i), P, N, clamp=False) for i in range(len(scene.lights))]
    base = np.asarray(scene.material.emission) + np.asarray(scene.material.ambient) * np.asarray(
        scene.ambient
    )
    np.testing.assert_allclose(base + sum(rows), shade(scene, P, N, clamp=False), atol=1e-12)
    with pytest.raises(ValueError, match="light index must be 0 to"):
        light_scene(scene, len(scene.lights))


def test_compose_strip_takes_any_rows_of_sums():
    """The per-pixel seam: sums of pixels (k, 3) compose as a shader's per-vertex ones do."""
    scene = Scene(material=find_preset("gold"))
    rng = np.random.default_rng(3)
    sums = {k: rng.uniform(0, 2, (17, 3)) for k in ("ambient", "diffuse", "specular")}
    colors = np.clip(term_colors(scene.material, sums)["sum"], 0, 1)
    strip = compose_strip(scene, sums, colors)
    assert strip.tiles["sum"].shape == (17, 3)
    np.testing.assert_array_equal(strip.overflow, np.any(colors != strip.terms["sum"], axis=1))


def test_the_overflow_mask_holds_at_the_edge_of_the_clamp():
    """A sum of exactly 1 is not clamped; the next double above it is."""
    from explorer.core.material import Material

    m = Material(ambient=(1, 1, 1), diffuse=(0, 0, 0), specular=(0, 0, 0), emission=(0, 0, 0))
    scene = Scene(material=m, ambient=(0, 0, 0))
    edge = [1.0, np.nextafter(1.0, 2.0), 0.9995, 0.0]
    sums = {k: np.zeros((4, 3)) for k in ("ambient", "diffuse", "specular")}
    sums["ambient"][:, 1] = edge
    strip = compose_strip(scene, sums, np.clip(sums["ambient"], 0, 1))
    np.testing.assert_array_equal(strip.overflow, [False, True, False, False])


@pytest.mark.parametrize("precision", ["float32", "float64"])
@pytest.mark.parametrize("index", range(7))
@pytest.mark.parametrize("mode", ["weighted", "raw"])
def test_the_compiled_bytes_are_the_tiles_bytes(index, precision, mode):
    """strip_bytes (one compiled pass over the sums as the shader keeps them) gives the bytes of
    compose_strip's tiles, and its overflow mask, exactly: grey sums, three.js's f90, both
    precisions."""
    if index < 6:
        scene = _scenes()[index]
    else:  # grey lights: the shader keeps (n, 1) sums
        grey = {
            "type": "point",
            "position": [0, 3, 0],
            "diffuse": [0.7] * 3,
            "specular": [0.7] * 3,
            "ambient": [0.1] * 3,
        }
        scene = Scene(material=find_preset("gold"), lights=(grey,))
    mesh = get_mesh("teapot")
    sh = Shader(scene, mesh.positions, mesh.normals, precision=precision, faces=mesh.faces)
    tiles, overflow = shader_strip_bytes(sh, mode)
    strip = shader_strip(sh, mode)
    want = np.stack([to_bytes(strip.tiles[t]) for t in TERMS])
    np.testing.assert_array_equal(tiles, want)
    np.testing.assert_array_equal(overflow, strip.overflow)
    if index == 6:
        assert kept_sums(sh)[1]["diffuse"].shape[1] == 1  # (the grey path was taken)


def test_the_strip_bytes_under_hdr_are_the_shown_tiles():
    scene = Scene(material=find_preset("gold"), hdr={"exposure": 1.0, "tone_map": "clamp"})
    mesh = get_mesh("sphere")
    sh = Shader(scene, mesh.positions, mesh.normals, precision="float64", clamp=False)
    tiles, overflow = shader_strip_bytes(sh)
    strip = shader_strip(sh)
    np.testing.assert_array_equal(tiles[4], to_bytes(shown(sh.colors, scene)))
    np.testing.assert_array_equal(overflow, strip.overflow)
    assert overflow.any()
