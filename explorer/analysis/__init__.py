"""What accuracy costs: per-vertex pictures compared with the per-pixel reference, the measured
table, the advice drawn from it, and the report.

May import: :mod:`explorer.core`, :mod:`explorer.geometry`, :mod:`explorer.shading`,
:mod:`explorer.render`; matplotlib inside the plot only. The window uses only the comparison and
the advice.
"""
