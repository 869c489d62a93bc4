"""Progress of a long run on stderr, through tqdm: a "compiling" phase, then a width-aware bar with
ETA and the punch displacement on a terminal, or plain periodic lines (no ``\\r``) in a log file."""
from __future__ import annotations

import sys
import time

from tqdm import tqdm

from jaxform.cli import raise_if_stopped


class Progress:
    """``on_progress(step, n_steps, t, punch_displacement_m, elapsed_s)`` callback of
    :func:`jaxform.forming.run`; call :meth:`start` before the run and :meth:`done` after it.

    On a terminal: a tqdm bar (percent, punch displacement, elapsed, ETA; the ETA counts from the
    first chunk, after compilation). Otherwise one plain line every ``every_s`` seconds and at the end.
    """

    def __init__(self, stream=None, quiet: bool = False, every_s: float = 10.0, label: str = "forming"):
        self.stream = stream or sys.stderr
        self.quiet = quiet
        self.every_s = every_s
        self.label = label
        self.tty = bool(getattr(self.stream, "isatty", lambda: False)())
        self.bar = None
        self.n_steps = None
        self.last_line = -float("inf")
        self.done_steps = 0

    def start(self, n_steps: int, what: str = "") -> None:
        """Say that compilation is under way (the first chunk compiles the step)."""
        if self.quiet:
            return
        self.n_steps = int(n_steps)
        msg = f"{self.label} {what}: compiling the step (the first chunk takes longest)..." if what else \
            f"{self.label}: compiling the step (the first chunk takes longest)..."
        if self.tty:
            self.bar = tqdm(total=self.n_steps, file=self.stream, dynamic_ncols=True, unit="step", desc="compiling",
                            bar_format="{desc}: {percentage:5.1f}%|{bar}| {n_fmt}/{total_fmt} [{elapsed}<{remaining}]{postfix}")
        else:
            print(msg, file=self.stream, flush=True)

    def __call__(self, step, n_steps, t, disp, elapsed):
        raise_if_stopped()  # a SIGTERM whose exception a hook swallowed stops the run here, at a chunk's end
        if self.quiet:
            return
        if self.n_steps is None:
            self.start(n_steps)
        if self.bar is not None:
            if self.bar.desc == "compiling":
                self.bar.set_description(self.label)
                self.bar.reset(total=self.n_steps)  # rate and ETA from now on: compilation is not a rate
                self.bar.initial = self.bar.n = int(step)
            self.bar.set_postfix_str(f"punch {disp * 1e3:.2f} mm", refresh=False)
            self.bar.update(int(step) - self.bar.n)
            return
        now = time.perf_counter()
        if now - self.last_line >= self.every_s or step >= n_steps:
            self.last_line = now
            print(f"{self.label}: step {step}/{n_steps} ({100 * step / max(n_steps, 1):.1f}%), punch "
                  f"{disp * 1e3:.2f} mm, elapsed {elapsed:.0f} s", file=self.stream, flush=True)

    def done(self) -> None:
        if self.bar is not None:
            self.bar.close()
            self.bar = None


__all__ = ["Progress"]
