"""A long job stepped from a front end's event loop, for both front ends (no toolkit here): the
controller's progress port (:class:`~explorer.app.controller.ports.Progress`) gives ``step`` and
``cancel``; the front end calls :meth:`Steps.next` from its loop (Qt's timer, the page's server
loop) until it says the job is over, shows its :attr:`~Steps.done`, :attr:`~Steps.total` and
:attr:`~Steps.text`, and its Cancel calls :meth:`Steps.cancel`."""

from __future__ import annotations


class Steps:
    """The job ``title`` of ``total`` steps, saying ``text``: ``step()`` does one unit and
    returns ``(done, text)`` (``text`` None: the text stays) while there is more, None when
    finished; ``cancel()`` is called once when the user cancels."""

    def __init__(self, title: str, text: str, total: int, step, cancel):
        self.title, self.text, self.total = title, text, int(total)
        self.done = 0
        self.running = True
        self._step, self._cancel = step, cancel

    def next(self) -> bool:
        """One step; False once the job is over (finished, or cancelled before)."""
        if not self.running:
            return False
        out = self._step()
        if out is None:
            self.running = False
            return False
        self.done, self.text = out[0], out[1] or self.text
        return True

    def cancel(self) -> None:
        """The user's Cancel: no more steps, and the job's ``cancel()`` (once)."""
        if self.running:
            self.running = False
            self._cancel()

    def as_dict(self) -> dict:
        """Plain values (the page's state): title, text, done, total, running."""
        return {
            "title": self.title,
            "text": self.text,
            "done": self.done,
            "total": self.total,
            "running": self.running,
        }
