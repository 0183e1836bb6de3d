"""The accuracy report: ``accuracy.md`` (published as ``docs/accuracy.md``) and its plot from a
measured table.

:func:`markdown` fills the template ``templates/accuracy.md`` (shipped with the package) with
the table's numbers: the prose lives in the template, and each small function here makes one
value of it (a table, a list, a sentence). The template is :class:`string.Template` text
(``${name}`` placeholders) with one addition, optional sections::

    <!-- if name -->
    lines kept only when the value ``name`` is not empty
    <!-- end name -->

(the marker lines themselves never reach the output). :func:`findings` writes the sentences
with numbers, :func:`plot` draws error against time with the Pareto front
(:func:`pareto_front`), :func:`table_bytes` is the table as ``accuracy.json``.
"""

from __future__ import annotations

import io
import json
import math
import re
import statistics
from collections.abc import Callable, Mapping, Sequence
from importlib import resources
from string import Template

from explorer.analysis.advice import mesh_for_error, short_count
from explorer.core.atomic import write_atomic
from explorer.core.errors import ExplorerError

#: the report's template, in this package's data
TEMPLATE = "templates/accuracy.md"

_SECTION = re.compile(r"^<!-- if (\w+) -->\n(.*?)^<!-- end \1 -->\n", re.M | re.S)


def fill(template: str, values: Mapping[str, str]) -> str:
    """``template`` with its optional sections resolved and its placeholders filled.

    A section (``<!-- if name -->`` ... ``<!-- end name -->``, each on a line of its own) is
    kept when ``values[name]`` is not empty and dropped with its marker lines otherwise. Every
    placeholder must have a value and every value a place: a mismatch is an ExplorerError
    (a template and its code out of step).
    """
    used = {m["named"] or m["braced"] for m in Template.pattern.finditer(template)} - {None}
    used |= {m[1] for m in _SECTION.finditer(template)}
    if used != set(values):
        raise ExplorerError(
            f"report template and values differ: without a value {sorted(used - set(values))}, "
            f"without a place {sorted(set(values) - used)}"
        )
    text = _SECTION.sub(lambda m: m[2] if values[m[1]] else "", template)
    return Template(text).substitute(values)


def template_text() -> str:
    """The report's template (:data:`TEMPLATE`)."""
    return resources.files(__package__).joinpath(TEMPLATE).read_text(encoding="utf-8")


# -- reading the table -----------------------------------------------------------------------------


def rows_where(table: dict, *, adaptive: bool = False, **match) -> list[dict]:
    """The table's rows matching every ``key=value``; adaptive rows only with
    ``adaptive=True`` (then only they)."""
    return [
        r
        for r in table["rows"]
        if all(r.get(k) == v for k, v in match.items()) and (r["mesh"] == "adaptive") == adaptive
    ]


def _first(table: dict, **match) -> dict:
    """The first row matching (see :func:`rows_where`), or an empty dict."""
    found = rows_where(table, **match)
    return found[0] if found else {}


def fmt(x, digits: int = 3) -> str:
    """A number for a table cell: ``–`` for None, integers as they are, others to ``digits``
    significant digits (whole numbers from 100 up)."""
    if x is None:
        return "–"
    if isinstance(x, int):
        return str(x)
    if x == 0:
        return "0"
    if abs(x) >= 100:
        return f"{x:.0f}"
    return f"{x:.{digits}g}"


def pareto_front(times: Sequence[float], errors: Sequence[float]) -> list[int]:
    """Indices of the points no other point beats in both time and error (lower is better
    in both), ordered by time. A point equal to another in both is kept once."""
    pts = sorted(range(len(times)), key=lambda i: (times[i], errors[i]))
    front = []
    best = math.inf
    for i in pts:
        if errors[i] < best:
            front.append(i)
            best = errors[i]
    return front


def _labels(table: dict) -> list[str]:
    return [x["label"] for x in table["scene"]["materials"]]


# -- the Markdown ----------------------------------------------------------------------------------


def markdown(table: dict, *, plot: str | None, command: str) -> str:
    """``accuracy.md`` from a measured table (:func:`explorer.analysis.benchmark.run_bench`).

    plot : the picture's path relative to the Markdown file (None: not drawn, not linked)
    command : the command that measured the table, named in the first paragraph
    """
    return fill(template_text(), report_values(table, plot=plot, command=command))


def report_values(table: dict, *, plot: str | None, command: str) -> dict[str, str]:
    """Every value of the report's template (see :func:`markdown`)."""
    sc = table["scene"]
    adaptive = rows_where(table, adaptive=True, side=table["main_side"])
    values = {
        "command": command,
        "quick": " **Quick run: a small table for tests, not a measurement.**"
        if table["quick"]
        else "",
        "side": str(table["main_side"]),
        "light": str(
            sc["light"].get("to_light", sc["light"].get("direction"))
        ),  # older tables: direction
        "ambient": str(sc["ambient"]),
        "materials": "; ".join(
            f"{x['label']} (shininess {x['shininess']:g}, specular {x['specular'][0]:g}, "
            f"diffuse {x['diffuse'][0]:g})"
            for x in sc["materials"]
        ),
        "plot": plot or "",
        "findings": "\n".join(f"- {line}" for line in findings(table)),
        "tessellation": _per_material(table, _tessellation_table),
        "per_pixel": "\n".join(
            _row(x["material"], f"{x['pixels']:,}", fmt(x["shade_ms"])) for x in table["per_pixel"]
        ),
        "adaptive": _per_material(table, _adaptive_table) if adaptive else "",
        "adaptive_base": adaptive[0]["base"] if adaptive else "",
        "model_match": _per_material(table, _model_match_table),
        "sizes": _per_material(table, _size_table) if len(table["sides"]) > 1 else "",
        "how_fine": "\n".join(_how_fine_row(table, x["shininess"]) for x in sc["materials"]),
    }
    return {**_machine_values(table), **values}


def _machine_values(table: dict) -> dict[str, str]:
    """The machine section's values and the run's repeats."""
    m = table["machine"] or {}
    gl = m.get("opengl", {})
    la, lb = m.get("load_before"), m.get("load_after")
    return {
        "date": str(m.get("date", "?")),
        "cpu": str(m.get("cpu", "?")),
        "cores": str(m.get("cores", "?")),
        "usable_cores": str(m.get("usable_cores", "?")),
        "memory": str(m.get("memory", "?")),
        "os": str(m.get("os", "?")),
        "opengl": f"{gl.get('renderer', '?')} ({gl.get('version', '?')})" if gl else "",
        "versions": ", ".join(f"{k} {val}" for k, val in m.get("versions", {}).items()),
        "load": f"{la} before, {lb} after" if la or lb else "",
        "runs": "1 run" if table["repeats"] == 1 else f"{table['repeats']} runs",
    }


def _per_material(table: dict, make: Callable[[dict, str], list[str]]) -> str:
    """One ``### material`` heading and table per material, ``make(table, label)`` giving the
    table's lines."""
    return "\n\n".join(
        "\n".join([f"### {label}", "", *make(table, label)]) for label in _labels(table)
    )


def _row(*cells) -> str:
    """A Markdown table row."""
    return "| " + " | ".join(str(c) for c in cells) + " |"


def _errors(r: dict) -> tuple[str, str, str]:
    """A row's RMSE, max and peak cells (``–`` where the row is missing)."""
    return fmt(r.get("rmse")), fmt(r.get("max")), fmt(r.get("peak"))


def _mesh(r: dict) -> tuple[str, str]:
    """A row's tessellation and vertex count cells."""
    return f"{r['mesh']} {r['resolution']}", f"{r['vertices']:,}"


def _tessellation_table(table: dict, label: str) -> list[str]:
    """Per-vertex Blinn against per-pixel Blinn, one row per tessellation: times of the three
    paths, errors of float64 and float32."""
    main = table["main_side"]
    out = [
        "| mesh | vertices | shade f64 ms | shade f32 ms | plan off ms | render ms | RMSE | max "
        "| peak | f32 max | f32-f64 | plan off Δ |",
        "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|",
    ]
    for r in rows_where(table, material=label, variant="blinn", side=main):
        key = dict(material=label, side=main, mesh=r["mesh"], resolution=r["resolution"])
        f32 = _first(table, variant="blinn float32", **key)
        off = _first(table, variant="blinn plan off", **key)
        out.append(_row(*_mesh(r), fmt(r["shade_ms"]), fmt(f32.get("shade_ms")),
                        fmt(off.get("shade_ms")), fmt(r["render_ms"]), *_errors(r),
                        fmt(f32.get("max")), fmt(f32.get("vs_float64")),
                        fmt(off.get("vs_float64"))))  # fmt: skip
    return out


def _adaptive_table(table: dict, label: str) -> list[str]:
    """Adaptive refinement, one row per threshold."""
    out = [
        "| threshold | vertices | refine + shade ms | render ms | RMSE | max | peak |",
        "|---:|---:|---:|---:|---:|---:|---:|",
    ]
    for r in rows_where(table, adaptive=True, side=table["main_side"], material=label):
        out.append(_row(f"{r['resolution']:g}", f"{r['vertices']:,}", fmt(r["shade_ms"]),
                        fmt(r["render_ms"]), *_errors(r)))  # fmt: skip
    return out


def _model_match_table(table: dict, label: str) -> list[str]:
    """Per-vertex Phong n and Blinn 4n against per-pixel Phong n, after the per-pixel line."""
    main = table["main_side"]
    out = [
        "| mesh | vertices | phong shade ms | render ms | phong RMSE | phong max | phong peak "
        "| blinn 4n shade ms | 4n RMSE | 4n max | 4n peak |",
        "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|",
    ]
    for x in table["model_match"]:
        if x["material"] == label:
            out.append(_row("per pixel", "–", "–", "–", 0, 0, 0, "–", *_errors(x)))
    for r in rows_where(table, material=label, variant="phong", side=main):
        b = _first(table, material=label, variant="blinn 4n", side=main, mesh=r["mesh"],
                   resolution=r["resolution"])  # fmt: skip
        out.append(_row(*_mesh(r), fmt(r["shade_ms"]), fmt(r["render_ms"]), *_errors(r),
                        fmt(b.get("shade_ms")), *_errors(b)))  # fmt: skip
    return out


def _size_table(table: dict, label: str) -> list[str]:
    """``RMSE / max`` of each tessellation at every picture size."""
    sides = table["sides"]
    out = [
        _row("mesh", "vertices", *(f"{s}x{s}" for s in sides)),
        "|---|---:|" + "---:|" * len(sides),
    ]
    for r in rows_where(table, material=label, variant="blinn", side=table["main_side"]):
        cells = []
        for s in sides:
            x = _first(table, material=label, variant="blinn", side=s, mesh=r["mesh"],
                       resolution=r["resolution"])  # fmt: skip
            cells.append(f"{fmt(x['rmse'])} / {x['max']}" if x else "–")
        out.append(_row(*_mesh(r), *cells))
    return out


def _how_fine_row(table: dict, shininess: float) -> str:
    """One material's row of the mesh_for_error table: every pixel within 1, 2, 4 levels and
    the RMSE within 1, for the UV sphere and the icosphere."""
    main = table["main_side"]
    cells = []
    for metric, bound in (("max", 1), ("max", 2), ("max", 4), ("rmse", 1)):
        parts = []
        for mesh in ("sphere", "icosphere"):
            try:
                rec = mesh_for_error(shininess, (main, main), bound, metric=metric, mesh=mesh,
                                     table=table)  # fmt: skip
            except ExplorerError:
                continue
            parts.append(
                f"{mesh} {rec.resolution} ({short_count(rec.vertices)})"
                if rec.resolution is not None
                else f"> {mesh} {rec.finest[0]}"
            )
        cells.append("<br>".join(parts) or "–")
    return _row(f"{shininess:g}", *cells)


# -- the findings ----------------------------------------------------------------------------------


def findings(table: dict) -> list[str]:
    """Sentences with numbers from the table (so the text always matches the data)."""
    labels = _labels(table)
    out = [s for label in labels if (s := _tessellation_finding(table, label))]
    out += [s for s in (_float32_finding(table), _plan_finding(table)) if s]
    out += [s for label in labels if (s := _adaptive_finding(table, label))]
    out += [s for s in [_size_finding(table)] if s]
    out += [
        f"{x['material']}: Blinn with exponent 4n against Phong n, both per pixel: RMSE "
        f"{fmt(x['rmse'])}, worst pixel {x['max']} levels."
        for x in table["model_match"]
    ]
    out += [s for s in (_render_finding(table, labels), _per_pixel_finding(table)) if s]
    return out


def _tessellation_finding(table: dict, label: str) -> str | None:
    """The coarsest and finest UV sphere of a material, and the recommendations."""
    main = table["main_side"]
    rows = rows_where(table, material=label, variant="blinn", side=main, mesh="sphere")
    if not rows:
        return None
    n = rows[0]["shininess"]
    coarse, fine = rows[0], rows[-1]
    rec1 = mesh_for_error(n, (main, main), 1.0, metric="rmse", table=table)
    recm = mesh_for_error(n, (main, main), 2.0, metric="max", table=table)
    s = (
        f"{label} (n = {n:g}): sphere {coarse['resolution']} is off by {coarse['max']} "
        f"levels at worst (RMSE {fmt(coarse['rmse'])}), sphere {fine['resolution']} by "
        f"{fine['max']} (RMSE {fmt(fine['rmse'])}); "
    )
    s += (
        f"RMSE within 1 level from sphere {rec1.resolution} ({rec1.vertices:,} vertices), "
        if rec1.resolution is not None
        else "no measured sphere has RMSE within 1 level, "
    )
    return s + (
        f"every pixel within 2 levels from sphere {recm.resolution}."
        if recm.resolution is not None
        else f"no measured sphere keeps every pixel within 2 levels "
        f"(sphere {recm.finest[0]}: {recm.finest[2]:g})."
    )


def _blinn_twin(table: dict, r: dict) -> dict:
    """The float64 Blinn row of the same material, size and tessellation as ``r``."""
    return _first(table, variant="blinn", material=r["material"], side=r["side"],
                  mesh=r["mesh"], resolution=r["resolution"])  # fmt: skip


def _float32_finding(table: dict) -> str | None:
    """float32 against float64: colour difference and speed."""
    f32 = [r for r in table["rows"] if r["path"] == "float32" and "vs_float64" in r]
    if not f32:
        return None
    worst = max(r["vs_float64"] for r in f32)
    pairs = [
        b["shade_ms"] / max(r["shade_ms"], 1e-9)
        for r in f32
        if (b := _blinn_twin(table, r)) and r["vertices"] >= 10_000
    ]
    s = f"float32 colours are within {fmt(worst)} levels of float64 at every vertex"
    if pairs:
        s += (
            f"; on meshes of 10k+ vertices float32 shades {statistics.median(pairs):.2g}x "
            "as fast (median)"
        )
    return s + "."


def _plan_finding(table: dict) -> str | None:
    """The plan off against on: colour difference and time."""
    off = [r for r in table["rows"] if r["path"] == "plan off"]
    if not off:
        return None
    ratios = [
        r["shade_ms"] / max(b["shade_ms"], 1e-9)
        for r in off
        if (b := _blinn_twin(table, r)) and r["vertices"] >= 10_000
    ]
    worst = max(r.get("vs_float64", 0.0) for r in off)
    s = f"the plan changes no colour (plan-off differs by at most {worst:.2g} levels)"
    if ratios:
        s += (
            f"; the full-generality numpy path takes {statistics.median(ratios):.2g}x the "
            "planned float64 time on 10k+ vertices (median)"
        )
    return s + "."


def _adaptive_finding(table: dict, label: str) -> str | None:
    """A material's best adaptive row against the smallest uniform mesh as good."""
    main = table["main_side"]
    ada = rows_where(table, adaptive=True, side=main, material=label)
    uni = rows_where(table, variant="blinn", side=main, material=label)
    if not ada or not uni:
        return None
    best = min(ada, key=lambda r: r["rmse"])
    match = [r for r in uni if r["rmse"] <= best["rmse"]]
    s = (
        f"{label}, adaptive: threshold {best['resolution']:g} gives RMSE "
        f"{fmt(best['rmse'])} (worst pixel {best['max']}) with {best['vertices']:,} "
        f"vertices in {fmt(best['shade_ms'])} ms; "
    )
    if not match:
        return s + "no measured uniform mesh is as good."
    u = min(match, key=lambda r: r["vertices"])
    return s + (
        f"the smallest uniform mesh as good, {u['mesh']} {u['resolution']}, has "
        f"{u['vertices']:,} vertices (worst pixel {u['max']})."
    )


def _size_finding(table: dict) -> str | None:
    """How the error of a tessellation changes between the smallest and largest picture."""
    sizes = sorted(table["sides"])
    if len(sizes) < 2:
        return None
    lo, hi = sizes[0], sizes[-1]
    change, growth = [], []
    for r in rows_where(table, variant="blinn", side=lo):
        (h,) = rows_where(table, variant="blinn", side=hi, material=r["material"],
                          mesh=r["mesh"], resolution=r["resolution"]) or (None,)  # fmt: skip
        if h is not None and r["rmse"] >= 0.5:
            change.append(abs(h["rmse"] / r["rmse"] - 1.0))
            growth.append(h["max"] - r["max"])
    if not change:
        return None
    return (
        f"picture size: between {lo}x{lo} and {hi}x{hi} the RMSE of a tessellation "
        f"changes by {100 * statistics.median(change):.2g}% (median; at most "
        f"{100 * max(change):.2g}%): the error belongs to the surface, not to the "
        f"pixels; the worst pixel grows by up to {max(growth)} levels with the size "
        "(more pixels sample the worst spot)."
    )


def _render_finding(table: dict, labels: list[str]) -> str | None:
    """What a VTK frame costs, small and large, and shading the largest mesh."""
    main = table["main_side"]
    render = rows_where(table, variant="blinn", side=main, material=labels[0]) if labels else []
    if not render:
        return None
    big = max(render, key=lambda r: r["vertices"])
    small = min(render, key=lambda r: r["vertices"])
    return (
        f"a {main}x{main} VTK frame takes {fmt(small['render_ms'])} ms with "
        f"{small['vertices']:,} vertices and {fmt(big['render_ms'])} ms with "
        f"{big['vertices']:,}; shading the largest mesh (float64) takes "
        f"{fmt(big['shade_ms'])} ms."
    )


def _per_pixel_finding(table: dict) -> str | None:
    """What the per-pixel reference itself costs."""
    pp = table["per_pixel"]
    if not pp:
        return None
    main = table["main_side"]
    return (
        f"the per-pixel reference costs {fmt(statistics.median(x['shade_ms'] for x in pp))} "
        f"ms per {main}x{main} picture here (numpy ray-sphere hits + engine shading of "
        f"{pp[0]['pixels']:,} pixels), no VTK."
    )


# -- the plot and the table file -------------------------------------------------------------------


def plot(table: dict, path, *, overwrite: bool = False) -> bool:
    """Draw accuracy.png (:func:`plot_png`), written atomically to ``path`` (an existing file
    only with ``overwrite``). Returns False (and writes nothing) when matplotlib is not
    installed (it is the optional ``bench`` extra)."""
    png = plot_png(table)
    if png is None:
        return False
    write_atomic(path, png, overwrite=overwrite)
    return True


def plot_png(table: dict) -> bytes | None:
    """The PNG bytes of accuracy.png: error against time per frame for each material, the
    Pareto front marked; None when matplotlib is not installed."""
    try:  # the optional ``bench`` extra, imported only to draw
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        from matplotlib.ticker import FuncFormatter, NullFormatter
    except ImportError:
        return None
    plain = FuncFormatter(lambda x, _pos: f"{x:g}")
    main = table["main_side"]
    labels = [x["label"] for x in table["scene"]["materials"]]
    series = [
        ("sphere", "blinn", "o", "C0", "UV sphere, float64"),
        ("sphere", "blinn float32", "s", "C1", "UV sphere, float32"),
        ("sphere", "blinn plan off", "x", "C3", "UV sphere, plan off"),
        ("icosphere", "blinn", "^", "C2", "icosphere, float64"),
        ("icosphere", "blinn float32", "v", "C4", "icosphere, float32"),
        ("adaptive", "blinn", "*", "k", "adaptive (refine_highlights)"),
    ]
    fig, axes = plt.subplots(2, len(labels), figsize=(4.2 * len(labels), 7.5), squeeze=False)
    for col, label in enumerate(labels):
        pp = [x for x in table["per_pixel"] if x["material"] == label]
        for row, metric in enumerate(("rmse", "max")):
            ax = axes[row][col]
            ts, es = [], []
            for mesh, variant, marker, color, name in series:
                rows = rows_where(table, material=label, variant=variant, side=main, mesh=mesh,
                                  adaptive=mesh == "adaptive")  # fmt: skip
                t = [r["shade_ms"] + r["render_ms"] for r in rows]
                e = [max(float(r[metric]), 0.05) for r in rows]
                ax.scatter(t, e, marker=marker, color=color, s=22, label=name, alpha=0.8)
                ts += t
                es += e
            if ts:
                front = pareto_front(ts, es)
                ax.step([ts[i] for i in front], [es[i] for i in front], where="post",
                        color="k", lw=1.0, label="Pareto front")  # fmt: skip
                ax.scatter([ts[i] for i in front], [es[i] for i in front], s=70,
                           facecolors="none", edgecolors="k", lw=1.0)  # fmt: skip
            if pp:
                ax.axvline(pp[0]["shade_ms"], color="grey", ls="--", lw=1.0,
                           label="per-pixel shading")  # fmt: skip
            ax.axhline(1.0, color="grey", ls=":", lw=0.8)
            ax.set_xscale("log")
            ax.set_yscale("log")
            for axis in (ax.xaxis, ax.yaxis):
                axis.set_major_formatter(plain)
                axis.set_minor_formatter(NullFormatter())
            ax.grid(True, which="both", alpha=0.2)
            if row == 0:
                n = table["scene"]["materials"][col]["shininess"]
                ax.set_title(f"{label} (n = {n:g})")
            if row == 1:
                ax.set_xlabel("shade + render per frame (ms)")
            if col == 0:
                ax.set_ylabel(("RMSE" if metric == "rmse" else "worst pixel") + " (1/255 levels)")
    handles, names = axes[0][0].get_legend_handles_labels()
    fig.legend(handles, names, loc="lower center", ncol=len(names), fontsize=8, frameon=False)
    m = table["machine"] or {}
    fig.suptitle(
        f"Per-vertex shading against the per-pixel reference, {main}x{main} "
        f"({m.get('cpu', '?')}, {m.get('usable_cores', '?')} cores)",
        fontsize=10,
    )
    fig.tight_layout(rect=(0, 0.04, 1, 1))
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=90)
    plt.close(fig)
    return buf.getvalue()


def table_bytes(table: dict) -> bytes:
    """The table as the bytes of ``accuracy.json`` (what :func:`explorer.analysis.advice.load_table`
    reads)."""
    return (json.dumps(table, indent=1, sort_keys=False) + "\n").encode("utf-8")
