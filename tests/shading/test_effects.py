"""Effects beyond the local model (issue 6): shadows, Fresnel, energy-conserving specular, HDR,
translucency in front of an opaque object; their plan decisions and golden pictures.

Goldens live in tests/golden/effects/ (tolerance and regenerating: tests/helpers/imagecompare.py).
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from helpers.imagecompare import check_golden, compare
from helpers.scenes import scenes
from hypothesis import given, settings
from hypothesis import strategies as st

import explorer
from explorer.cli import main
from explorer.core import tolerances as tol
from explorer.core.errors import ValidationError
from explorer.core.hdr import TONE_MAPS, energy_warnings
from explorer.core.scene import load_scene
from explorer.geometry import meshes as M
from explorer.geometry.meshes import Mesh
from explorer.render.images import read_png
from explorer.shading.display import display_colors, engine_clamps, vertex_colors
from explorer.shading.effects import EFFECTS, LEVELS, Effect, energy_factor, schlick
from explorer.shading.effects.hdr import display, expose, srgb_decode, srgb_encode, tone_map
from explorer.shading.equation import equation_shade
from explorer.shading.plan import make_plan

SPHERE_Z, SPHERE_R = 0.6, 0.4


def sphere_over_plane(res_sphere=24, res_plane=48) -> Mesh:
    """A sphere of radius 0.4 centred 0.6 above the plane z = 0 (both facing out/up)."""
    s, p = M.sphere(res_sphere), M.plane(res_plane)
    pos = np.vstack([s.positions * SPHERE_R + [0, 0, SPHERE_Z], p.positions])
    nrm = np.vstack([s.normals, p.normals])
    faces = np.vstack([s.faces, p.faces + len(s.positions)])
    return Mesh(pos, nrm, faces, "sphere_over_plane")


SMALL = sphere_over_plane(8, 6)
CONVEX = M.icosphere(1)


def fibonacci(n: int) -> np.ndarray:
    """n unit vectors spread evenly over the upper hemisphere (z > 0), equal solid angle."""
    i = np.arange(n) + 0.5
    z = 1.0 - i / n
    phi = i * math.pi * (3.0 - math.sqrt(5.0))
    r = np.sqrt(1.0 - z * z)
    return np.stack([r * np.cos(phi), r * np.sin(phi), z], 1)


# -- the plan equals the full-generality reference, effects included -------------------------


@st.composite
def effect_scenes(draw):
    scene = draw(scenes(max_lights=3))
    m = scene["material"]
    if draw(st.booleans()):
        m["fresnel"] = draw(st.sampled_from([0.0, 0.04, 0.5, 1.0]))
    m["energy_conserving"] = draw(st.booleans())
    for light in scene["lights"]:
        light["shadows"] = draw(st.booleans())
    return scene


@settings(max_examples=40)
@given(effect_scenes(), st.sampled_from(["concave", "convex", "none"]))
def test_planned_effects_equal_full_generality(scene, which):
    mesh = {"concave": SMALL, "convex": CONVEX, "none": SMALL}[which]
    faces = None if which == "none" else mesh.faces
    loaded = load_scene(scene)
    P, N = mesh.positions, mesh.normals
    full = equation_shade(loaded, P, N, clamp=False, faces=faces)
    planned = explorer.shade(loaded, P, N, clamp=False, faces=faces)
    scale = max(1.0, float(np.abs(full).max(initial=0)))
    assert np.abs(planned - full).max(initial=0) <= tol.PLAN_ABS_TOL * scale
    fast = explorer.shade(loaded, P, N, precision="float32", faces=faces)
    assert np.abs(fast - np.clip(full, 0, 1)).max(initial=0) <= tol.FLOAT32_MAX_ABS_ERROR
    forced = explorer.Shader(loaded, P, N, precision="float64", clamp=False, faces=faces,
                             force_all=True)  # fmt: skip
    assert np.abs(forced.colors - full).max(initial=0) <= tol.PLAN_ABS_TOL * scale


# -- shadows ---------------------------------------------------------------------------------


def _in_shadow(points, direction=None, position=None):
    """Geometry: does the segment from each point toward the light cross the sphere's ball?
    Returns the distance from the sphere centre to that segment minus the radius (< 0: shadow)."""
    c = np.array([0.0, 0.0, SPHERE_Z])
    if direction is not None:
        d = np.broadcast_to(np.asarray(direction, float) / np.linalg.norm(direction), points.shape)
        tmax = np.full(len(points), np.inf)
    else:
        d = np.asarray(position, float) - points
        tmax = np.linalg.norm(d, axis=1)
        d = d / tmax[:, None]
    t = np.clip(np.einsum("ij,ij->i", c - points, d), 0.0, tmax)
    closest = points + t[:, None] * d
    return np.linalg.norm(closest - c, axis=1) - SPHERE_R


@pytest.mark.parametrize(
    "light",
    [
        {"type": "directional", "to_light": [0.0, 0.0, 1.0]},
        {"type": "directional", "to_light": [0.5, -0.3, 1.0]},
        {"type": "point", "position": [-0.2, 0.1, 1.6]},
    ],
)
def test_plane_under_sphere_is_shadowed_where_geometry_says(light):
    mesh = sphere_over_plane()
    scene = {
        "material": {"ambient": [0, 0, 0], "diffuse": [1, 1, 1]},
        "ambient": [0, 0, 0],
        "lights": [{**light, "shadows": True}],
    }
    c = explorer.shade(scene, mesh.positions, mesh.normals, faces=mesh.faces)
    plane = slice(len(mesh.positions) - 49 * 49, None)
    pts = mesh.positions[plane]
    gap = _in_shadow(
        pts, light.get("to_light"), light.get("position")
    )  # signed distance to the shadow edge
    lit = c[plane, 0]
    margin = 0.03  # the tessellated sphere is within 0.01 of the true one
    assert np.all(lit[gap < -margin] == 0.0)
    assert np.all(lit[gap > margin] > 0.0)
    assert (gap < -margin).sum() > 20  # the shadow is really there
    no = explorer.shade({**scene, "lights": [light]}, mesh.positions, mesh.normals)
    assert np.all(no[plane, 0][gap < -margin] > 0.0)  # and only because of shadows: true


def test_plan_skips_shadow_rays_where_they_cannot_matter():
    light = {"type": "directional", "to_light": [0.3, 0.2, 1.0], "shadows": True}
    scene = {"lights": [light, {"type": "directional", "to_light": [0, 1, 0]}]}
    mesh = sphere_over_plane(12, 16)
    sh = explorer.Shader(scene, mesh.positions, mesh.normals, faces=mesh.faces)
    _ = sh.colors
    facing = mesh.normals @ np.array(light["to_light"]) / np.linalg.norm(light["to_light"])
    assert sh.stats["shadow_rays"] == int((facing > -1e-6).sum()) < len(facing)
    assert sh.plan.lights[0].shadows and not sh.plan.lights[1].shadows
    # a convex mesh is not skipped (no convexity test is exact at every resolution); its rays
    # find no occluder
    convex = explorer.Shader(scene, CONVEX.positions, CONVEX.normals, faces=CONVEX.faces)
    _ = convex.colors
    facing = CONVEX.normals @ np.array(light["to_light"]) / np.linalg.norm(light["to_light"])
    assert convex.plan.shadows and convex.stats["shadow_rays"] == int((facing > -1e-6).sum())
    assert "every mesh, convex-looking ones too" in convex.plan.describe()
    plain = {**scene, "lights": [{**light, "shadows": False}, scene["lights"][1]]}
    unshadowed = explorer.Shader(plain, CONVEX.positions, CONVEX.normals, faces=CONVEX.faces)
    assert np.array_equal(convex.colors, unshadowed.colors)
    nofaces = explorer.Shader(scene, mesh.positions, mesh.normals)
    assert "no mesh faces" in nofaces.plan.describe() and not nofaces.plan.shadows
    forced = explorer.Shader(scene, CONVEX.positions, CONVEX.normals, faces=CONVEX.faces,
                             force_all=True)  # fmt: skip
    assert np.array_equal(forced.colors, convex.colors) or np.allclose(
        forced.colors, convex.colors, atol=1e-6
    )
    assert forced.stats["shadow_rays"] == len(CONVEX.positions)


def test_shadow_rays_are_cached_by_light_position():
    mesh = sphere_over_plane(12, 16)
    light = explorer.PointLight(position=(0.1, 0.0, 2.0), shadows=True)
    sh = explorer.Shader({"lights": [light]}, mesh.positions, mesh.normals, faces=mesh.faces)
    _ = sh.colors
    rays = sh.stats["shadow_rays"]
    sh.set_lights([light.replace(diffuse=(0.5, 0.2, 0.1))])  # colour only: no new rays
    _ = sh.colors
    assert sh.stats["shadow_rays"] == rays
    moved = light.replace(position=(0.4, 0.0, 2.0))
    sh.set_lights([moved])
    got = np.array(sh.colors)
    assert sh.stats["shadow_rays"] > rays
    fresh = explorer.Shader({"lights": [moved]}, mesh.positions, mesh.normals, faces=mesh.faces)
    assert np.array_equal(got, fresh.colors)
    sh.set_geometry(mesh.positions, mesh.normals)  # no faces: no shadows any more
    assert not sh.plan.shadows


# -- Fresnel -------------------------------------------------------------------------------


def test_fresnel_weights_the_specular_by_schlick():
    # infinite viewer along z, light at angle a from the viewer, normal on the bisector: the
    # highlight's centre (N = H), where the lobe is 1 and V·H = cos(a/2)
    angles = np.radians([0.0, 30.0, 60.0, 120.0, 160.0, 176.0])
    L = np.stack([np.sin(angles), np.zeros_like(angles), np.cos(angles)], 1)
    H = L + [0, 0, 1]
    H /= np.linalg.norm(H, axis=1, keepdims=True)
    f0 = 0.04
    mat = {"ambient": [0, 0, 0], "diffuse": [0, 0, 0], "specular": [1, 1, 1], "shininess": 50}
    spec = np.array(
        [
            explorer.shade(
                {
                    "material": {**mat, "fresnel": f0},
                    "ambient": [0, 0, 0],
                    "lights": [{"type": "directional", "to_light": L[i].tolist()}],
                },
                np.zeros((1, 3)),
                H[i : i + 1],
                clamp=False,
            )[0, 0]
            for i in range(len(L))
        ]
    )
    want = f0 + (1 - f0) * (1 - np.cos(angles / 2)) ** 5
    assert np.allclose(spec, want, rtol=1e-9, atol=1e-12)
    assert np.all(np.diff(spec) > 0)  # the highlight grows toward grazing
    assert spec[0] == pytest.approx(f0)
    assert np.allclose(schlick(f0, np.cos(angles)), want)


def test_fresnel_and_energy_changes_cost_what_they_should():
    mesh = M.sphere(16)
    scene = load_scene(
        {
            "material": {"specular": [1, 1, 1], "shininess": 20, "fresnel": 0.1,
                         "energy_conserving": True},
            "viewer": {"eye": [0, 1, 4]},
            "lights": [{"type": "point", "position": [2, 2, 2]}],
        }
    )  # fmt: skip
    sh = explorer.Shader(scene, mesh.positions, mesh.normals, precision="float64")
    _ = sh.colors
    for n in (40, 80):  # shininess with the energy factor: the lobe only, once bases are kept
        sh.set_material(sh.scene.material.replace(shininess=n))
        _ = sh.colors
    passes = sh.stats["pass"]
    sh.set_material(sh.scene.material.replace(shininess=160))
    got = np.array(sh.colors)
    assert sh.stats["pass"] == passes and sh.stats["lobe"] >= 1
    fresh = explorer.shade(sh.scene, mesh.positions, mesh.normals)
    assert np.abs(got - fresh).max() <= 1e-12
    sh.set_material(sh.scene.material.replace(fresnel=0.5))  # F changes: specular again
    assert np.abs(sh.colors - explorer.shade(sh.scene, mesh.positions, mesh.normals)).max() < 1e-12
    assert sh.stats["pass"] == passes + 1


# -- energy-conserving specular --------------------------------------------------------------


@pytest.mark.parametrize("model", ["phong", "blinn"])
def test_energy_conserving_lobe_narrows_without_dimming(model):
    N = fibonacci(20000)  # normals over the hemisphere facing the light and the viewer
    N[0] = (0.0, 0.0, 1.0)  # and the highlight's centre
    base = {"ambient": [0, 0, 0], "diffuse": [0, 0, 0], "specular": [1, 1, 1]}

    def total(n, on):
        scene = {
            "material": {**base, "shininess": n, "energy_conserving": on},
            "model": model,
            "ambient": [0, 0, 0],
            "lights": [{"type": "directional", "to_light": [0, 0, 1]}],
        }
        c = explorer.shade(scene, np.zeros_like(N), N, clamp=False)[:, 0]
        return c.max(), (c * N[:, 2]).mean()  # peak, and the picture's total (projected area)

    p10, t10 = total(10, True)
    p400, t400 = total(400, True)
    assert p400 / p10 == pytest.approx(energy_factor(model, 400) / energy_factor(model, 10))
    assert 0.5 < t400 / t10 < 1.5  # same light reflected overall
    q10, u10 = total(10, False)
    q400, u400 = total(400, False)
    assert q10 == q400 == pytest.approx(1.0) and u400 / u10 < 0.05  # unnormalised: dims
    assert energy_factor("phong", 0) == pytest.approx(1 / math.pi)
    assert energy_factor("blinn", 8) == pytest.approx(2 / math.pi)


# -- HDR -----------------------------------------------------------------------------------


def test_srgb_encoding_is_exact_and_invertible():
    y = np.linspace(0, 1, 1001)
    assert np.allclose(srgb_decode(srgb_encode(y)), y, atol=1e-12)
    assert srgb_encode(0.0031308) == pytest.approx(12.92 * 0.0031308)
    assert srgb_encode(0.5) == pytest.approx(1.055 * 0.5 ** (1 / 2.4) - 0.055)
    assert srgb_encode(1.0) == pytest.approx(1.0) and srgb_encode(0.0) == 0.0
    assert np.all(np.diff(srgb_encode(y)) > 0)
    lo = srgb_encode(0.0031308 - 1e-12)
    hi = srgb_encode(0.0031308 + 1e-12)
    assert abs(hi - lo) < 1e-6  # continuous at the joint


@pytest.mark.parametrize("name", TONE_MAPS)
def test_tone_maps_are_monotone_into_unit_range(name):
    x = np.concatenate([np.linspace(0, 4, 400), [10, 100, 1e6]])
    y = tone_map(x, name)
    assert np.all((y >= 0) & (y <= 1)) and np.all(np.diff(y) >= 0) and y[0] == 0.0
    if name == "reinhard":
        assert tone_map(1.0, name) == pytest.approx(1 / 2) and y[-1] < 1
    if name == "aces":
        # at x = 1 the scaled input is a = 0.6: 0.6·1.536 / (0.6·2.048 + 0.14) by hand
        assert y[-1] == 1.0 and tone_map(1.0, name) == pytest.approx(0.9216 / 1.3688)
    assert np.allclose(expose(x, 1.0), 2 * x)


def test_hdr_shading_keeps_values_above_one_and_warns_on_kd_plus_ks(capsys):
    scene = {
        "material": {"diffuse": [0.9, 0.5, 0.5], "specular": [0.3, 0.3, 0.6], "shininess": 10},
        "lights": [{"type": "directional", "intensity": 3}],
        "hdr": {"exposure": -1, "tone_map": "aces"},
    }
    loaded = load_scene(scene)
    c = explorer.shade(loaded, np.zeros((1, 3)), [[0, 0, 1]], clamp=False)
    assert c.max() > 1
    d = display(c, loaded.hdr)
    assert np.all(d <= 1) and np.allclose(d, srgb_encode(tone_map(c * 0.5, "aces")))
    warns = energy_warnings(loaded.material)
    assert len(warns) == 2 and "R channel" in warns[0] and "B channel" in warns[1]
    assert "1.2" in warns[0]
    plan = make_plan(loaded).describe()
    assert "hdr" in plan and "R channel" in plan and "G channel" not in plan


def test_effect_keys_are_validated_with_clear_messages():
    bad = {
        "material": {"fresnel": 1.5, "energy_conserving": "yes"},
        "lights": [{"type": "point", "shadows": 1}],
        "hdr": {"exposure": 40, "tone_map": "filmic", "gamma": 2},
    }
    with pytest.raises(ValidationError) as e:
        load_scene(bad)
    msg = str(e.value)
    for part in (
        "material.fresnel: must be in [0, 1], got 1.5",
        "material.energy_conserving: must be true or false",
        "lights[0].shadows: must be true or false",
        "hdr.exposure: must be in [-16, 16]",
        "hdr.tone_map: must be one of clamp, reinhard, aces",
        "hdr.gamma: unknown key; allowed keys: exposure, tone_map",
    ):
        assert part in msg, (part, msg)


def test_effect_keys_round_trip_and_default_off():
    s = load_scene({})
    assert s.hdr is None and s.material.fresnel is None and not s.material.energy_conserving
    assert not any(lt.shadows for lt in s.lights)
    mapping = {
        "material": {"fresnel": 0.2, "energy_conserving": True},
        "lights": [{"type": "spot", "shadows": True}],
        "hdr": {"exposure": 0.5, "tone_map": "reinhard"},
    }
    s = load_scene(mapping)
    assert load_scene(s.to_mapping()) == s


def test_plan_command_shows_each_effect(tmp_path, capsys):
    f = tmp_path / "scene.yaml"
    f.write_text(
        "material: {specular: [0.5, 0.5, 0.5], shininess: 30, fresnel: 0.04,"
        " energy_conserving: true}\n"
        "hdr: {exposure: 1, tone_map: aces}\nmesh: sphere\n"
        "lights:\n  - {type: directional, to_light: [1, 1, 1], shadows: true}\n"
        "  - {type: point, position: [2, 2, 2]}\n"
    )
    assert main(["plan", str(f)]) == 0
    out = capsys.readouterr().out
    assert "fresnel" in out and "Schlick F0 = 0.04" in out
    assert "(n+8)/(8π)" in out
    assert "aces tone map" in out
    assert "mesh sphere: " in out and "through the mesh's BVH" in out
    assert "shadows is false" in out


# -- golden pictures -------------------------------------------------------------------------


_GLOSSY = {
    "ambient": [0.05, 0.05, 0.08],
    "diffuse": [0.25, 0.35, 0.6],
    "specular": [0.6, 0.6, 0.6],
    "shininess": 60,
}

EFFECT_SCENES = {
    "shadow": (
        {
            "material": {"ambient": [0.15, 0.15, 0.15], "diffuse": [0.8, 0.7, 0.5]},
            "viewer": {"eye": [0.0, -2.6, 2.4]},
            "lights": [{"type": "directional", "to_light": [0.6, 0.3, 1.0], "shadows": True}],
        },
        "sphere_over_plane",
    ),
    "fresnel": (
        {
            "material": {**_GLOSSY, "specular": [1, 1, 1], "fresnel": 0.04},
            "viewer": {"to_viewer": [0, 0, 1]},
            "lights": [{"type": "directional", "to_light": [0.643, 0.2, -0.766]}],
        },
        "sphere",
    ),
    "energy_n10": (
        {
            "material": {**_GLOSSY, "shininess": 10, "energy_conserving": True},
            "lights": [{"type": "directional", "to_light": [1, 1, 1], "intensity": 0.5}],
            "hdr": {"exposure": 0, "tone_map": "reinhard"},
        },
        "sphere",
    ),
    "energy_n200": (
        {
            "material": {**_GLOSSY, "shininess": 200, "energy_conserving": True},
            "lights": [{"type": "directional", "to_light": [1, 1, 1], "intensity": 0.5}],
            "hdr": {"exposure": 0, "tone_map": "reinhard"},
        },
        "sphere",
    ),
    "hdr": (
        {
            "material": _GLOSSY,
            "lights": [
                {"type": "point", "position": [1.5, 1.5, 2.0], "intensity": 4},
                {"type": "directional", "to_light": [-1, 0, 0.3], "intensity": 1.5},
            ],
            "hdr": {"exposure": -0.5, "tone_map": "aces"},
        },
        "teapot",
    ),
}


def _effect_mesh(name):
    return sphere_over_plane() if name == "sphere_over_plane" else M.get_mesh(name)


def _effect_image(renderer, name):
    mapping, mesh_name = EFFECT_SCENES[name]
    return renderer.render(load_scene(mapping), _effect_mesh(mesh_name))


@pytest.mark.parametrize("name", sorted(EFFECT_SCENES))
def test_golden_effect(renderer, name):
    check_golden(f"effects/{name}", _effect_image(renderer, name))


def test_golden_effects_show_their_effect(renderer):
    for name, key in (("shadow", None), ("fresnel", "fresnel"), ("hdr", "hdr")):
        mapping, mesh_name = EFFECT_SCENES[name]
        off = dict(mapping)
        if key == "fresnel":
            off["material"] = {k: v for k, v in mapping["material"].items() if k != "fresnel"}
        elif key == "hdr":
            off.pop("hdr")
        else:
            off["lights"] = [{k: v for k, v in lt.items() if k != "shadows"}
                             for lt in mapping["lights"]]  # fmt: skip
        img_off = renderer.render(load_scene(off), _effect_mesh(mesh_name))
        assert not compare(_effect_image(renderer, name), img_off).ok, name
    a, b = _effect_image(renderer, "energy_n10"), _effect_image(renderer, "energy_n200")
    assert not compare(a, b).ok
    assert b.max() >= a.max() - 2  # narrower, not dimmer


def _translucent_over_opaque(renderer):

    front = load_scene(
        {
            "material": {
                "ambient": [0.02, 0.1, 0.02],
                "diffuse": [0.1, 0.6, 0.15],
                "specular": [0.6, 0.6, 0.6],
                "shininess": 40,
                "opacity": 0.45,
            },
            "viewer": {"eye": [0.0, 0.0, 3.2]},
            "lights": [{"type": "directional", "to_light": [0.3, 0.5, 1]}],
        }
    )
    sphere = M.sphere(48)
    back = M.cube()
    back = Mesh(back.positions * [1.3, 0.35, 0.35] + [0, 0, -1.0], back.normals, back.faces)
    back_scene = front.replace(material=explorer.Material(diffuse=(0.8, 0.3, 0.1)))
    back_colors = vertex_colors(back_scene, back)
    return renderer.render(front, sphere, backdrop=(back, back_colors)), renderer, sphere, front


def test_golden_translucent_in_front_of_opaque(renderer):
    img, *_ = _translucent_over_opaque(renderer)
    check_golden("effects/translucent_over_opaque", img)
    # the bar shows through the sphere: the centre row differs from the row above the bar
    assert np.abs(img[200].astype(int) - img[140].astype(int)).max() > 20


def test_translucent_is_drawn_the_same_from_both_sides(renderer):
    """Sorted drawing: viewed from the front and from behind (mirrored viewer) a symmetric
    translucent sphere under a symmetric light gives the mirrored picture."""
    sphere = M.sphere(48)
    scene = load_scene(
        {
            "material": {"diffuse": [0.2, 0.5, 0.9], "specular": [0.5, 0.5, 0.5],
                         "shininess": 20, "opacity": 0.5},
            "two_sided": True,
            "viewer": {"eye": [0.0, 0.0, 3.0]},
            "lights": [{"type": "directional", "to_light": [0, 1, 0]}],
        }
    )  # fmt: skip
    a = renderer.render(scene, sphere)
    b = renderer.render(scene.replace(viewer=explorer.Viewer(eye=(0.0, 0.0, -3.0))), sphere)
    c = compare(a, b[:, ::-1])  # tessellation and silhouette pixels differ a little
    assert c.mean_abs < 1.0 and c.different_fraction < 0.03


def test_render_cli_hdr_flags(tmp_path, capsys):
    out = tmp_path / "hdr.png"
    argv = ["render", "--out", str(out), "--exposure", "1", "--tone-map", "aces",
            "--light-intensity", "2"]  # fmt: skip
    assert main(argv) == 0

    img = read_png(out)
    base = tmp_path / "plain.png"
    assert main(["render", "--out", str(base), "--light-intensity", "2"]) == 0
    assert not compare(img, read_png(base)).ok
    assert main(["render", "--out", str(tmp_path / "x.png"), "--exposure", "99"]) == 2
    assert "--exposure" in capsys.readouterr().err
    # kd + ks > 1 with HDR: a warning naming the channel
    f = tmp_path / "s.yaml"
    f.write_text("material: {diffuse: [0.9, 0.2, 0.2], specular: [0.5, 0.5, 0.5]}\nhdr: true\n")
    assert main(["render", str(f), "--out", str(tmp_path / "w.png")]) == 0
    err = capsys.readouterr().err
    assert "warning:" in err and "R channel" in err and "G channel" not in err


def test_display_without_hdr_is_the_engines_clamped_colours():
    scene = explorer.Scene()
    mesh = M.icosphere(1)
    c = explorer.shade(scene, mesh.positions, mesh.normals, faces=mesh.faces)
    assert display(c, None) is c and engine_clamps(scene)
    assert np.array_equal(vertex_colors(scene, mesh), c)
    assert np.array_equal(display_colors(scene, mesh.positions, mesh.normals), c)
    hdr = load_scene({"hdr": {"exposure": 1, "tone_map": "reinhard"}})
    assert not engine_clamps(hdr)
    raw = explorer.shade(hdr, mesh.positions, mesh.normals, clamp=False)
    assert np.array_equal(display_colors(hdr, mesh.positions, mesh.normals), display(raw, hdr.hdr))


# -- the effect interface --------------------------------------------------------------------


def test_effects_have_one_name_each_and_declare_a_known_cost():
    names = [e.name for e in EFFECTS]
    assert len(set(names)) == len(names)
    assert all(e.invalidates in LEVELS for e in EFFECTS)
    plan = make_plan(load_scene({}))
    assert [n for n, _ in plan.effects] == names  # every effect planned, in registry order


class _Doubled(Effect):
    """A toy effect: twice the specular, folded into the kernel rows, its own plan row."""

    name = "doubled"
    invalidates = "specular"

    def plan(self, scene, terms):
        return (2.0 if terms.specular else 1.0), [(self.name, "in", "toy: specular × 2")]

    def specular_factor(self, value):
        return value

    def weights(self, scene, light, at):
        return None, 2.0


def test_a_new_effect_needs_no_change_in_plan_shader_or_equation(monkeypatch):
    from explorer.shading import display, equation, plan, shader

    scene = load_scene(
        {
            "material": {"diffuse": [0.3, 0.3, 0.3], "specular": [0.4, 0.5, 0.6],
                         "shininess": 12, "fresnel": 0.2},
            "lights": [{"type": "point", "position": [1, 2, 3]}],
        }
    )  # fmt: skip
    mesh = M.sphere(12)
    P, N = mesh.positions, mesh.normals
    without = explorer.shade(scene, P, N, clamp=False)
    for module in (plan, shader, equation, display):
        monkeypatch.setattr(module, "EFFECTS", (*EFFECTS, _Doubled()))
    assert "doubled" in make_plan(scene).describe()
    got = explorer.shade(scene, P, N, clamp=False)
    full = equation_shade(scene, P, N, clamp=False)
    assert np.abs(got - full).max() <= tol.PLAN_ABS_TOL * max(1.0, float(full.max()))
    spec = explorer.Shader(scene, P, N, precision="float64", clamp=False).terms["specular"]
    diffuse_only = scene.replace(material=scene.material.replace(specular=(0.0, 0.0, 0.0)))
    base = explorer.shade(diffuse_only, P, N, clamp=False)
    s_m = np.asarray(scene.material.specular)
    assert np.allclose(got - base, 2 * (without - base)) and np.allclose(got - base, s_m * spec)
