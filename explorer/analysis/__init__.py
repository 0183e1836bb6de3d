"""What accuracy costs: per-vertex pictures compared with the per-pixel reference, the measured
table, the advice drawn from it, and the report.

- :mod:`~explorer.analysis.comparison`: a per-vertex picture against the per-pixel reference
  of the same view, and the heat map of the difference;
- :mod:`~explorer.analysis.advice`: the measured table shipped with the package and what it
  advises (:func:`~explorer.analysis.advice.mesh_for_error`);
- :mod:`~explorer.analysis.refine`: adaptive refinement of a mesh where per-vertex shading
  misses;
- :mod:`~explorer.analysis.benchmark`: the measurement behind the table
  (``phong-explorer bench accuracy``);
- :mod:`~explorer.analysis.report`: the table as Markdown (from ``templates/accuracy.md``), a
  plot and JSON.

May import: :mod:`explorer.core`, :mod:`explorer.geometry`, :mod:`explorer.shading`,
:mod:`explorer.render`; matplotlib inside the plot only. The window uses only the comparison and
the advice.
"""
