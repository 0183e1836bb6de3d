"""The desktop explorer window.

May import everything below it (:mod:`explorer.core`, :mod:`explorer.geometry`,
:mod:`explorer.shading`, :mod:`explorer.render`) and, of :mod:`explorer.analysis`, the comparison
and the advice only. PyVista / VTK are imported inside the functions that open windows.
"""
