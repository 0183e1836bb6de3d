"""How the kernels are generated: the layouts declared once, the variant tables and the
dispatch written from them, and what compiling a light loop asks of numba."""

from __future__ import annotations

import numba as nb
import numpy as np
import pytest

from explorer.core import lightrow
from explorer.core.slots import Slots
from explorer.shading import codegen, layout
from explorer.shading import kernels as K


def test_slots_take_the_next_offset_by_width():
    s = Slots()
    assert (s.slot(), s.slot(3), s.slot()) == (0, 1, 4)
    assert s.count == 5
    with pytest.raises(ValueError, match="at least 1 wide"):
        s.slot(0)
    v = Slots()
    assert (v.value(0.5), v.value(2.0)) == (0, 1)
    assert v.values == [0.5, 2.0] and v.count == 2
    s.values.clear()
    with pytest.raises(ValueError, match="every slot"):
        s.value(1.0)  # a layout with slots of no value cannot take one


def _names(module, prefix):
    return {n: getattr(module, n) for n in vars(module) if n.startswith(prefix)}


@pytest.mark.parametrize(
    ("module", "prefix", "count"),
    [
        (layout, "O_", "N_OPTS"),
        (layout, "R_", "N_ROWS"),
        (layout, "K_", "N_CONSTS"),
        (layout, "B_", "N_BOUNDS"),
    ],
)
def test_each_layout_is_one_run_of_distinct_slots(module, prefix, count):
    slots = _names(module, prefix)
    assert sorted(slots.values()) == list(range(getattr(module, count)))


def test_the_constants_are_the_layouts_values_in_slot_order():
    k = K.constants(np.float64)
    assert len(k) == layout.N_CONSTS
    assert k[layout.K_ONE] == 1.0 and k[layout.K_INF] == np.inf


def test_a_light_row_s_columns_tile_it():
    # each column's width is what lies up to the next one; together they fill N_PARAMS
    cols = sorted(_names(lightrow, "P_").values())
    assert cols[0] == 0 and cols[-1] < lightrow.N_PARAMS
    assert lightrow.P_POS + 3 == lightrow.P_AXIS and lightrow.P_F0 + 1 == lightrow.N_PARAMS


def test_the_dispatch_calls_the_variant_its_code_names():
    calls = []
    src = codegen.dispatch_source("run", "a, b, code", "variant", (3, 7))
    space = {"variant": lambda *args: calls.append(args)}
    exec(src, space)  # noqa: S102 - the source under test
    space["run"]("x", "y", 7)
    space["run"]("x", "y", 3)
    space["run"]("x", "y", 5)  # no such variant: nothing runs
    assert calls == [("x", "y", 7), ("x", "y", 3)]


def test_every_light_loop_code_names_its_loop_once():
    loops = [codegen.loop_of(c) for c in codegen.LIGHT_LOOPS]
    assert len(set(codegen.LIGHT_LOOPS)) == len(loops) == 18
    assert all(
        codegen.valid(lp) and codegen.loop_code(lp) == c
        for lp, c in zip(loops, codegen.LIGHT_LOOPS, strict=True)
    )
    assert len(set(codegen.COMPOSE_VARIANTS)) == 18


def test_a_light_loop_is_compiled_without_numba_inlining_its_rows(monkeypatch):
    # numba's IR inliner copies and types the callee again at each call (the cold compile's
    # largest Python cost): a light loop takes its ~20 scratch rows through intrinsics, and
    # inlines only its sums (_add_light) and its power (pow32, log2_32, exp2_32: numba types
    # the power's overload twice, so its chain comes twice)
    from numba.core import inline_closurecall

    inlined = []
    real = inline_closurecall.InlineWorker.inline_ir

    def counting(self, caller_ir, block, i, callee_ir, *args, **kw):
        inlined.append(callee_ir.func_id.func_qualname)
        return real(self, caller_ir, block, i, callee_ir, *args, **kw)

    monkeypatch.setattr(inline_closurecall.InlineWorker, "inline_ir", counting)
    code = codegen.loop_code(codegen.Loop(codegen.SRC_ROWS, codegen.LOBE_PHONG, False))

    @nb.njit(cache=False, _nrt=False)
    def one_loop(scr, m, q, y, k):
        K._light(scr, m, q, y, k, True, True, code)

    T = np.float32
    one_loop(np.zeros((layout.N_ROWS + 1) * K.ROW, T), 3, np.zeros(24, T), T(3), K.constants(T))
    assert "_row" not in inlined and "_row_checked" not in inlined
    assert len(inlined) <= 12, inlined


def _pass(scene, precision):
    from explorer.geometry.meshes import torus
    from explorer.shading.shader import Shader

    mesh = torus(12)
    s = Shader(scene, mesh.positions, mesh.normals, precision=precision, tier="compiled")
    return np.asarray(s.colors, np.float64)


LIT = {
    "material": {"emission": [0.1, 0.05, 0.0], "diffuse": [0.6, 0.5, 0.4], "shininess": 20.0},
    "viewer": {"eye": [0, 0, 5]},
    "lights": [
        {"type": "point", "position": [2.0, 1.5, 3.0], "ambient": [0, 0, 0]},
        {"type": "directional", "to_light": [0.3, 1.0, 0.5], "ambient": [0, 0, 0]},
    ],
}


@pytest.mark.parametrize("precision", ["float32", "float64"])
def test_the_kernels_run_the_light_loops_from_their_table(monkeypatch, precision):
    # the light loops are called through the table of entry points given with the lights
    # (kernels.loop_table), not linked into the pass: a table of no loops adds no light
    real = _pass(LIT, precision)
    none = np.zeros(64, np.int64)
    none.flags.writeable = False  # (as the real table: no other signature of shade to compile)
    monkeypatch.setattr(K, "loop_table", lambda dtype, codes=None: none)
    dark = _pass(LIT, precision)
    monkeypatch.undo()
    unlit = {**LIT, "lights": [dict(lt, diffuse=[0] * 3, specular=[0] * 3) for lt in LIT["lights"]]}
    assert np.array_equal(dark, _pass(unlit, precision))
    assert (real - dark).max() > 0.3  # (and with the table, the lights shine)


def test_each_light_loop_is_a_kernel_of_its_own():
    # compiled once per precision and cached on its own (so the cache's guard and its list of
    # files know it: warm.dispatchers), and no copy of any in the pass's compiled code: numba
    # links a called function's code into its caller, and LLVM optimised the 36 light loops
    # again at every level of the chain (_light_loop, _block, _task, shade's parallel loop,
    # shade, fixup: most of the cold compile's LLVM time, benchmarks/bench_compile.py --warm)
    from explorer.shading import warm

    names = {f"explorer.shading.kernels._light_{c}" for c in codegen.LIGHT_LOOPS}
    assert names <= set(warm.dispatchers())
    for dtype in (np.float32, np.float64):
        table = K.loop_table(dtype)
        assert np.count_nonzero(table) == len(codegen.LIGHT_LOOPS) == 18
        assert table is K.loop_table(dtype)  # (once per process)
        for code in codegen.LIGHT_LOOPS:
            assert K.light_signature(dtype) in getattr(K, f"_light_{code}").overloads
    _pass(LIT, "float32")  # (compiled, or loaded from the cache)
    shade = getattr(K.shade, "dispatcher", K.shade)
    assert shade.overloads
    for cres in shade.overloads.values():
        # numba's private API (numba.core.codegen.CPUCodeLibrary): the module other code links
        linked = cres.library._get_module_for_linking()
        defined = [f.name for f in linked.functions if not f.is_declaration]
        assert defined and not [f for f in defined if "_light_overload" in f]


def _fresh_tables(monkeypatch):
    """No light loop in this process's tables yet (as in a new process; numba's dispatchers
    keep what they compiled, so a loop already compiled is only entered again)."""
    monkeypatch.setattr(K, "_tables", {})
    monkeypatch.setattr(K, "_filled", {})


@pytest.mark.parametrize("precision", ["float32", "float64"])
def test_a_pass_compiles_only_the_light_loops_it_calls(monkeypatch, precision):
    # issue 38 item 5: a session compiles the loops its scenes use, not the 36 (each loop is
    # 1-2 s of the cold compile); the table holds those a pass asked for (kernels.pass_loops)
    real = _pass(LIT, precision)
    _fresh_tables(monkeypatch)
    compiled = []
    for code in codegen.LIGHT_LOOPS:
        d = getattr(K, f"_light_{code}")
        monkeypatch.setattr(
            d, "compile", lambda sig, d=d, c=code: compiled.append(c) or type(d).compile(d, sig)
        )
    assert np.array_equal(_pass(LIT, precision), real)
    table = K.loop_table(precision, [])
    asked = [c for c in codegen.LIGHT_LOOPS if table[c]]
    # (a float32 pass asks for its loops in float64 too, for the redo of its ambiguous lanes)
    assert sorted(set(compiled)) == asked and 1 <= len(asked) <= 4, (compiled, asked)
    shiny = {**LIT, "material": {**LIT["material"], "specular": [0.5] * 3}}
    again = _pass(shiny, precision)  # a specular lobe: its loops join
    assert len([c for c in codegen.LIGHT_LOOPS if table[c]]) > len(asked)
    assert (again != real).any()


def _scene_passes(precision):
    """The colours of the background compile's scenes (explorer.shading.warm.SCENES: every
    light path, model, viewer, effect) on a concave mesh with shadows, with the material and
    viewer changes the window makes (passes of the diffuse, the specular or the lobe alone)."""
    from explorer.geometry.meshes import torus
    from explorer.shading import warm
    from explorer.shading.shader import Shader

    mesh = torus(12)
    out = []
    for scene in warm.SCENES:
        s = Shader(
            {"material": warm.MATERIAL, **scene},
            mesh.positions,
            mesh.normals,
            precision=precision,
            faces=mesh.faces,
            tier="compiled",
        )
        out.append(np.array(s.colors))
        material = s.scene.material
        for change in (
            {"diffuse": [0.2, 0.5, 0.9]},
            {"shininess": 12.0},
            {"shininess": 0.0},
            {"specular": [0.0, 0.0, 0.0]},
        ):
            s.set_material(material.replace(**change))
            out.append(np.array(s.colors))
        s.set_viewer({"eye": [0.5, 1.0, 4.0]})
        out.append(np.array(s.colors))
    return out


@pytest.mark.parametrize("precision", ["float32", "float64"])
def test_a_pass_asks_for_every_light_loop_it_calls(monkeypatch, precision):
    # a loop the table lacks is skipped (its entry is 0): so each pass's table must hold every
    # loop the kernels call for it. Here each pass gets the loops kernels.pass_loops names and
    # no other, and every colour is as with all 36 loops
    for dtype in (np.float32, np.float64):
        K.loop_table(dtype)  # every loop in the tables (a float32 pass redoes lanes in float64)
    full = _scene_passes(precision)
    loop_table = K.loop_table

    def only_asked(dtype, codes=None):
        everything = loop_table(dtype)
        table = np.zeros_like(everything)
        wanted = codegen.LIGHT_LOOPS if codes is None else codes
        table[list(wanted)] = everything[list(wanted)]
        table.flags.writeable = False
        return table

    monkeypatch.setattr(K, "loop_table", only_asked)
    for got, want in zip(_scene_passes(precision), full, strict=True):
        assert np.array_equal(got, want)


def test_while_the_loops_are_compiled_elsewhere_a_pass_compiles_none(monkeypatch):
    # the background compile's main process (explorer.shading.warm.exercise with its partner)
    # compiles the kernels that call the light loops but not the loops: its partner does
    _fresh_tables(monkeypatch)
    compiled = []
    for code in codegen.LIGHT_LOOPS:
        d = getattr(K, f"_light_{code}")
        monkeypatch.setattr(d, "compile", lambda sig, c=code: compiled.append(c))
    K.loops_elsewhere(True)
    try:
        dark = _pass(LIT, "float64")
        assert not K.loop_table(np.float64).any() and not compiled
    finally:
        K.loops_elsewhere(False)
    unlit = {**LIT, "lights": [dict(lt, diffuse=[0] * 3, specular=[0] * 3) for lt in LIT["lights"]]}
    monkeypatch.undo()
    assert np.array_equal(dark, _pass(unlit, "float64"))  # (no loop ran)
