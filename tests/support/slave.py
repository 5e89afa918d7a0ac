"""An fmpy FMU2Slave whose log messages are recorded: the misuse tests of both FMUs call
the FMI functions through it and read why a call was refused."""

import ctypes
import itertools

from fmpy import calloc, free
from fmpy.fmi1 import FMICallException, printLogMessage
from fmpy.fmi2 import (
    FMU2Slave,
    fmi2CallbackAllocateMemoryTYPE,
    fmi2CallbackFreeMemoryTYPE,
    fmi2CallbackFunctions,
    fmi2CallbackLoggerTYPE,
    fmi2Discard,
    fmi2Error,
    fmi2OK,
    fmi2Real,
    fmi2String,
    fmi2ValueReference,
    fmi2Warning,
    fmi2Integer,
)


REFUSED = (fmi2Discard, fmi2Error)  # a refused call: not OK, not Warning, never Fatal


# fmpy's native logger proxy (fmpy.logging.addLoggerProxy: formats the variadic message) keeps
# ONE process-wide target logger, the last one it was given, and fmpy's default callbacks go
# through it too. A per-instance Python callback would be left dangling there once its
# instance is gone (a crash at the next message of any FMU in the process), so a single
# permanent callback dispatches the messages by instance name.
_RECORDERS = {}  # instance name -> list of (status, category, message)


def _dispatch(env, instance, status, category, message):
    name = (instance or b"").decode("utf-8", "replace")
    entry = (
        int(status),
        (category or b"").decode("utf-8", "replace"),
        (message or b"").decode("utf-8", "replace"),
    )
    logs = _RECORDERS.get(name)
    if logs is not None:
        logs.append(entry)
    else:
        printLogMessage(env, instance, status, category, message)


_LOGGER = fmi2CallbackLoggerTYPE(_dispatch)
_instance_count = itertools.count()


class Slave:
    """An FMU2Slave instance whose log messages are recorded in self.logs."""

    def __init__(self, unzipdir, md, name):
        name = f"{name}_{next(_instance_count)}"  # unique: the messages are routed by name
        self.name = name
        self.logs = []  # (status, category, message)
        _RECORDERS[name] = self.logs
        self.callbacks = fmi2CallbackFunctions()
        self.callbacks.logger = _LOGGER
        self.callbacks.allocateMemory = fmi2CallbackAllocateMemoryTYPE(calloc)
        self.callbacks.freeMemory = fmi2CallbackFreeMemoryTYPE(free)
        from fmpy.logging import addLoggerProxy  # formats the variadic messages

        addLoggerProxy(ctypes.byref(self.callbacks))
        self.fmu = FMU2Slave(
            guid=md.guid,
            unzipDirectory=unzipdir,
            modelIdentifier=md.coSimulation.modelIdentifier,
            instanceName=name,
        )
        self.fmu.instantiate(callbacks=self.callbacks, loggingOn=False)
        self.vrs = {v.name: v.valueReference for v in md.modelVariables}
        self.t = 0.0

    # --- calls returning the FMI status (fmpy raises above Warning: caught here) --------
    @staticmethod
    def _status(fn, *args):
        try:
            res = fn(*args)
        except FMICallException as e:
            return e.status
        return res

    def _set(self, fn, ctype, refs, values):
        n = len(refs)
        return self._status(fn, self.fmu.component, (fmi2ValueReference * n)(*refs), n, (ctype * n)(*values))

    def _get(self, fn, ctype, refs):
        n = len(refs)
        val = (ctype * n)()
        return self._status(fn, self.fmu.component, (fmi2ValueReference * n)(*refs), n, val), list(val)

    def set_real(self, refs, values):
        return self._set(self.fmu.fmi2SetReal, fmi2Real, refs, values)

    def get_real(self, refs):
        return self._get(self.fmu.fmi2GetReal, fmi2Real, refs)

    def set_integer(self, refs, values):
        return self._set(self.fmu.fmi2SetInteger, fmi2Integer, refs, values)

    def get_integer(self, refs):
        return self._get(self.fmu.fmi2GetInteger, fmi2Integer, refs)

    def do_step(self, h, t=None):
        t = self.t if t is None else t
        st = self._status(self.fmu.fmi2DoStep, self.fmu.component, t, h, 1)
        if st in (fmi2OK, fmi2Warning) and h > 0:
            self.t = t + h
        return st

    def set_debug_logging(self, on, categories):
        n = len(categories)
        cats = (fmi2String * n)(*[c.encode() for c in categories])
        return self._status(self.fmu.fmi2SetDebugLogging, self.fmu.component, 1 if on else 0, n, cats)

    def setup(self, start=0.0):
        self.t = start
        return self._status(self.fmu.fmi2SetupExperiment, self.fmu.component, 0, 0.0, start, 0, 0.0)

    def enter_init(self):
        return self._status(self.fmu.fmi2EnterInitializationMode, self.fmu.component)

    def exit_init(self):
        return self._status(self.fmu.fmi2ExitInitializationMode, self.fmu.component)

    def reset(self):
        self.t = 0.0
        return self._status(self.fmu.fmi2Reset, self.fmu.component)

    def terminate(self):
        return self._status(self.fmu.fmi2Terminate, self.fmu.component)

    def init(self, reals=None, integers=None, start=0.0):
        """setupExperiment, enter, set start values, exit; all must be OK."""
        assert self.setup(start) == fmi2OK
        assert self.enter_init() == fmi2OK
        if integers:
            assert self.set_integer([self.vrs[k] for k in integers], list(integers.values())) == fmi2OK
        if reals:
            assert self.set_real([self.vrs[k] for k in reals], list(reals.values())) == fmi2OK
        assert self.exit_init() == fmi2OK, self.logs[-3:]

    def real(self, name):
        st, v = self.get_real([self.vrs[name]])
        assert st == fmi2OK
        return v[0]

    # --- log inspection ---------------------------------------------------------------
    def mark(self):
        return len(self.logs)

    def new_logs(self, mark):
        return self.logs[mark:]

    def assert_logged(self, mark, *keywords):
        """A message at Warning or worse since mark, containing every keyword (any case)."""
        msgs = [m for m in self.new_logs(mark) if m[0] >= fmi2Warning]
        assert msgs, f"no warning/error message logged (all since mark: {self.new_logs(mark)})"
        for kw in keywords:
            assert any(kw.lower() in m[2].lower() for m in msgs), f"no message mentions {kw!r}: {msgs}"

    def free(self):
        self.fmu.freeInstance()
        _RECORDERS.pop(self.name, None)
