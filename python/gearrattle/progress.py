"""A progress bar on stderr: points done, rate and time left; redrawn in place on a terminal,
a line per 10 % otherwise (make logs, CI)."""

import sys
import time


class Progress:
    def __init__(self, total, label, unit="points", stream=sys.stderr, width=30):
        self.total, self.label, self.unit = max(total, 1), label, unit
        self.stream, self.width = stream, width
        self.done, self.t0, self.last_decile = 0, time.perf_counter(), -1
        self.tty = hasattr(stream, "isatty") and stream.isatty()
        self._draw("")

    def update(self, n=1, note=""):
        self.done += n
        self._draw(note)

    def _draw(self, note):
        frac = min(self.done / self.total, 1.0)
        el = time.perf_counter() - self.t0
        rate = self.done / el if el > 0 else 0.0
        left = (self.total - self.done) / rate if rate > 0 else float("nan")
        fill = int(round(self.width * frac))
        line = (f"{self.label} [{'#' * fill}{'.' * (self.width - fill)}] {self.done}/{self.total}"
                f" {self.unit} {100 * frac:3.0f}%  {rate:.1f}/s  {el:.0f} s elapsed"
                + (f", ~{left:.0f} s left" if 0 < self.done < self.total else "")
                + (f"  {note}" if note else ""))
        if self.tty:
            self.stream.write("\r" + line[:150].ljust(150))
        else:
            decile = int(10 * frac)
            if decile == self.last_decile and self.done < self.total:
                return
            self.last_decile = decile
            self.stream.write(line + "\n")
        self.stream.flush()

    def close(self):
        if self.tty:
            self.stream.write("\n")
            self.stream.flush()
