"""The explorer: its state, its flows and its two front ends (the desktop window, the web page).

- :mod:`explorer.app.model`, :mod:`explorer.app.session`, :mod:`explorer.app.start`: the state,
  its actions and undo history, sessions, the start: plain Python that imports neither Qt, VTK
  nor PyVista (a second front end can reuse them).
- :mod:`explorer.app.view`, :mod:`explorer.app.difference`: the VTK view and the difference
  view's worker thread (VTK and PyVista imported inside functions; no Qt).
- :mod:`explorer.app.controller`: every flow of the explorer (open, save, export, undo, the
  difference and compare views) for any front end, through small ports; no GUI toolkit.
- :mod:`explorer.app.qt` and :mod:`explorer.app.qtmain`: the Qt window (PySide6, pyvistaqt), a
  thin binding of the controller.
- :mod:`explorer.app.web` (with :mod:`~explorer.app.web.page`, :mod:`~explorer.app.web.panel`,
  :mod:`~explorer.app.web.files`, :mod:`~explorer.app.web.compare`): the page in the browser and
  in Jupyter (trame, imported inside functions), the controller's second front end;
  :mod:`explorer.app.colours`, :mod:`explorer.app.sides`: colours as both front ends' controls
  show them, the compare view's side B.

May import everything below it (:mod:`explorer.core`, :mod:`explorer.geometry`,
:mod:`explorer.shading`, :mod:`explorer.render`) and, of :mod:`explorer.analysis`, the
comparison and the advice only. Importing this package imports nothing of Qt, VTK or PyVista.
"""
