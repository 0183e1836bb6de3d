"""The Qt front end: the window (:mod:`explorer.app.qt.window`), its control panel
(:mod:`~explorer.app.qt.panel`, :mod:`~explorer.app.qt.lightpanel`), menus and keys
(:mod:`~explorer.app.qt.menus`), the message log (:mod:`~explorer.app.qt.messages`), the compare
view's pane (:mod:`~explorer.app.qt.compare`), the view port's pictures
(:mod:`~explorer.app.qt.viewport`) and the turntable's progress dialog
(:mod:`~explorer.app.qt.turntable`). A thin binding of :class:`explorer.app.controller.Controller`:
widgets send intents, observe the store and draw; the window implements the controller's ports.

May import: PySide6, pyvistaqt, the controller, the model, the app's VTK view
(:mod:`explorer.app.view`) and the view port both front ends share (:mod:`explorer.app.viewport`,
:mod:`explorer.app.sides`, :mod:`explorer.app.handledrag`); the controller never imports it.
"""
