"""The desktop explorer.

- :mod:`explorer.app.model`, :mod:`explorer.app.session`, :mod:`explorer.app.start`: the state,
  its actions and undo history, sessions, the start: plain Python that imports neither Qt, VTK
  nor PyVista (a second front end can reuse them).
- :mod:`explorer.app.view`, :mod:`explorer.app.difference`: the VTK view and the difference
  view's worker thread (VTK and PyVista imported inside functions; no Qt).
- :mod:`explorer.app.controller`: every flow of the explorer (open, save, export, undo, the
  difference and compare views) for any front end, through small ports; no GUI toolkit.
- :mod:`explorer.app.qt` and :mod:`explorer.app.qtmain`: the Qt window (PySide6, pyvistaqt), a
  thin binding of the controller.

May import everything below it (:mod:`explorer.core`, :mod:`explorer.geometry`,
:mod:`explorer.shading`, :mod:`explorer.render`) and, of :mod:`explorer.analysis`, the
comparison and the advice only. Importing this package imports nothing of Qt, VTK or PyVista.
"""
