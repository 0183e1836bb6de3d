"""The panel model's rows of the lobe inset (:mod:`explorer.app.lobeinset`, docs/terms.md): the
set of lobes and how it is plotted, each lobe's visibility, the plot's incidence (the lit
sphere's drag). :mod:`explorer.app.panelmodel` calls :func:`lobe_rows` with its ``Row`` class
(this module imports nothing of the panel model: no cycle) and draws them as every other row.
"""

from __future__ import annotations

from explorer.analysis.lobes import QUANTITIES as LOBE_QUANTITIES
from explorer.analysis.lobes import VIEWS as LOBE_VIEWS
from explorer.app import lobeinset as LI


def _option(name: str):
    """A lobe option's edit: :func:`explorer.app.lobeinset.set_lobe_option`."""
    return lambda s, v: (LI.set_lobe_option, (name, v))


def lobe_rows(Row) -> list:
    """The lobe inset's rows, made with the panel model's ``Row`` class: which lobes, how
    they are plotted (docs/terms.md), then :func:`lobe_view_rows`."""
    several = lambda s: s.lobes != "selected"  # noqa: E731 - the rows' one test
    return [
        Row(
            "lobes",
            "view",
            "choice",
            lambda s: s.lobes,
            _option("lobes"),
            choices=LI.LOBE_SETS,
            tip="the inset's lobes: the selected light's, the three models', each light's, or "
            "sides A and B",
        ),
        Row(
            "lobe_view",
            "view",
            "choice",
            lambda s: s.lobe_view,
            _option("lobe_view"),
            visible=several,
            choices=LOBE_VIEWS,
            inline=True,
            tip="polar: the plane of incidence, the normal up; cartesian: against the view angle",
        ),
        Row(
            "lobe_quantity",
            "view",
            "choice",
            lambda s: s.lobe_quantity,
            _option("lobe_quantity"),
            visible=several,
            choices=LOBE_QUANTITIES,
            tip="intensity per unit light, the BRDF (intensity / (π N·L), 1/sr), or the "
            "directional albedo ρ(θ_i)",
        ),
        Row(
            "lobe_log",
            "view",
            "toggle",
            lambda s: s.lobe_log,
            _option("lobe_log"),
            visible=several,
            group="lobe_scale",
            tip="a log scale: four decades",
        ),
        Row(
            "lobe_ndl",
            "view",
            "toggle",
            lambda s: s.lobe_ndl,
            _option("lobe_ndl"),
            visible=several,
            group="lobe_scale",
            text="× N·L",
            tip="each value times N·L",
        ),
        *lobe_view_rows(Row, several),
    ]


def lobe_view_rows(Row, several) -> list:
    """Each lobe of the set drawn or not (the first :data:`~explorer.app.lobeinset.LOBE_ROWS`;
    ``several(state)``: the set has several lobes), and the plot's incidence (the lit
    sphere's)."""
    return [
        *(
            Row(
                f"show_lobe_{i + 1}",
                "view",
                "toggle",
                lambda s, i=i: i not in s.lobe_hidden,
                lambda s, v, i=i: (LI.set_lobe_shown, (i, bool(v))),
                visible=lambda s, i=i: several(s) and i < len(LI.lobe_set_all(s)),
                group="lobe_shown",
                label=f"lobe {i + 1}",
                text=f"lobe {i + 1}" if i == 0 else str(i + 1),  # (a line: lobe 1, 2, 3)
                tip=f"draw lobe {i + 1} of the inset's plot (the legend's line {i + 1}; a click "
                "on it there does the same)",
            )
            for i in range(LI.LOBE_ROWS)
        ),
        Row(
            "lobe_incidence",
            "view",
            "number",
            lambda s: s.lobe_incidence,
            lambda s, v: (LI.set_lobe_incidence, (v,)),
            optional=45.0,
            tip="the incidence θ_i the lobe plot and its lit sphere show (drag on the sphere); "
            "off: the selected light's",
        ),
    ]
