"""A background process the panel watches: its output read on a thread, its progress parsed,
stopped on Cancel. Blender's data is only touched on the main thread (the timer, or `wait`)."""

import collections
import os
import re
import signal
import subprocess
import threading

STEP = re.compile(r"\bstep (\d+)/(\d+)")


class Job:
    """One run of `sinmdm` or `sinmdm-train`; `finish` is called on the main thread when it ends."""

    def __init__(self, label, argv, finish):
        self.label = label
        self.argv = [str(a) for a in argv]
        self.finish = finish
        self.lines = collections.deque(maxlen=400)
        self.progress = 0.0
        self.cancelled = False
        self.done = False
        flags = {}
        if os.name == "nt":
            flags["creationflags"] = subprocess.CREATE_NEW_PROCESS_GROUP
        self.process = subprocess.Popen(
            self.argv,
            stdin=subprocess.DEVNULL,
            stdout=subprocess.PIPE,
            stderr=subprocess.STDOUT,
            text=True,
            errors="replace",
            **flags,
        )
        self.reader = threading.Thread(target=self._read, daemon=True)
        self.reader.start()

    def _read(self):
        for line in self.process.stdout:
            line = line.rstrip()
            self.lines.append(line)
            m = STEP.search(line)
            if m and int(m.group(2)) > 0:
                self.progress = int(m.group(1)) / int(m.group(2))

    def running(self):
        return self.process.poll() is None

    def cancel(self, timeout=120.0):
        """Asks the process to stop as Ctrl-C would (the trainer saves a checkpoint first), then
        waits for it; killed only if it does not stop within `timeout` seconds."""
        self.cancelled = True
        if self.running():
            if os.name == "nt":
                self.process.send_signal(signal.CTRL_BREAK_EVENT)
            else:
                self.process.send_signal(signal.SIGINT)
            try:
                self.process.wait(timeout)
            except subprocess.TimeoutExpired:
                self.process.kill()
                self.process.wait()
        self.reader.join()

    def wait(self):
        self.process.wait()
        self.reader.join()

    def tail(self, count=6):
        return "\n".join(list(self.lines)[-count:])

    def error(self):
        """What the process said when it failed: its error line(s), else its last lines."""
        code = self.process.returncode
        said = [line for line in self.lines if line.lower().startswith("error")]
        return f"{os.path.basename(self.argv[0])} exited with {code}: " + ("\n".join(said) or self.tail())


_current = None
_last = None


def current():
    """The job now running (one at a time), or None."""
    return _current


def last():
    """The job that ended last (its output stays readable), or None."""
    return _last


def start(job):
    global _current
    _current = job
    return job


def clear():
    global _current, _last
    _last, _current = _current, None
