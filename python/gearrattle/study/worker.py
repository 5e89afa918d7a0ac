"""The study's work on one process: the FMU extracted once per GUID, one FMU instance per thread
reused with fmi2Reset between points, and a batch of points run on it.

A point is set up the way a user sets up a fresh instance (fmi2SetupExperiment, the start values,
initialization), stepped to its duration in one fmi2DoStep, and its `stat_*` outputs read. A
point the FMU refuses is returned with status "refused" and the FMU's own error message; it is
not retried. Nothing here that holds a pointer leaves the process: batches come in as plain
values and go out as plain dicts."""

import ctypes
import io
import itertools
import os
import shutil
import tempfile
import threading
import time
import zipfile

from distributed.diagnostics.plugin import WorkerPlugin

from .model import STATS_FROM, read_model

_FMUS = {}  # GUID -> (extracted directory, Model), per process
_LOCK = threading.Lock()
_THREAD = threading.local()  # .instances: GUID -> Instance, one per thread
_LOGS = {}  # instance name -> list of (status, message), filled by the logger callback
_NAMES = itertools.count()


def install_fmu(guid, data):
    """Extract the FMU (its bytes) once per process; later calls with the same GUID are free."""
    with _LOCK:
        if guid not in _FMUS:
            path = tempfile.mkdtemp(prefix="gearrattle-fmu-")
            zipfile.ZipFile(io.BytesIO(data)).extractall(path)
            model = read_model(path)
            if model.guid != guid:
                raise ValueError(f"FMU bytes have GUID {model.guid}, expected {guid}")
            _FMUS[guid] = (path, model)
        return _FMUS[guid]


def uninstall_fmu(guid):
    """Remove the extracted FMU (a worker plugin's teardown)."""
    with _LOCK:
        entry = _FMUS.pop(guid, None)
    if entry:
        shutil.rmtree(entry[0], ignore_errors=True)


def _log(_env, instance, status, _category, message):
    logs = _LOGS.get((instance or b"").decode("utf-8", "replace"))
    if logs is not None:
        logs.append((int(status), (message or b"").decode("utf-8", "replace")))


def _make_logger():
    from fmpy.fmi2 import fmi2CallbackLoggerTYPE

    return fmi2CallbackLoggerTYPE(_log)


_LOGGER = None  # made on first use: fmpy is imported lazily, workers import this module early


def _route_messages():
    """fmpy's native proxy (it formats the variadic messages) sends every FMU's messages to the
    last Python logger it was given, process-wide: point it at ours before each point, so that
    other fmpy users in the same process (a test session) cannot take the messages away."""
    from fmpy.fmi2 import fmi2CallbackFunctions
    from fmpy.logging import addLoggerProxy

    global _LOGGER
    if _LOGGER is None:
        _LOGGER = _make_logger()
    cb = fmi2CallbackFunctions()
    cb.logger = _LOGGER
    addLoggerProxy(ctypes.byref(cb))
    return cb


class Instance:
    """One FMU instance, reused for point after point."""

    def __init__(self, unzipdir, model):
        from fmpy import calloc, free
        from fmpy.fmi2 import (FMU2Slave, fmi2CallbackAllocateMemoryTYPE,
                               fmi2CallbackFreeMemoryTYPE)

        self.model, self.unzipdir = model, unzipdir
        self.name = f"study{os.getpid()}_{next(_NAMES)}"
        self.logs = _LOGS.setdefault(self.name, [])
        self.callbacks = _route_messages()  # its logger becomes the formatting proxy
        self.callbacks.allocateMemory = fmi2CallbackAllocateMemoryTYPE(calloc)
        self.callbacks.freeMemory = fmi2CallbackFreeMemoryTYPE(free)
        self.fmu = FMU2Slave(guid=model.guid, unzipDirectory=unzipdir,
                             modelIdentifier=model.model_identifier, instanceName=self.name)
        self.fmu.instantiate(callbacks=self.callbacks, loggingOn=False)
        self.fresh = True
        self.metric_real = [v for v in model.metrics if v.type == "Real"]
        self.metric_int = [v for v in model.metrics if v.type != "Real"]

    def close(self):
        self.fmu.freeInstance()
        _LOGS.pop(self.name, None)

    def run(self, values, duration, record=(), sound=False):
        """Run one point: values = {parameter name: value}. Returns a dict of the metrics (and
        the recorded outputs, the sound columns), status, message and cpu_s."""
        from fmpy.fmi1 import FMICallException

        t0 = time.process_time()
        _route_messages()
        self.logs.clear()
        row, call = {}, "fmi2Reset"
        try:
            if not self.fresh:
                self.fmu.reset()
            self.fresh = False
            call = "fmi2SetupExperiment"
            self.fmu.setupExperiment(startTime=0.0, stopTime=duration)
            call = "fmi2Set*"
            self._set(values)
            call = "fmi2EnterInitializationMode"
            self.fmu.enterInitializationMode()
            call = "fmi2ExitInitializationMode"
            self.fmu.exitInitializationMode()
            call = "fmi2DoStep"
            if sound:
                from ..sound.study import point

                row.update(point(self.fmu, self.unzipdir, values, duration,
                                 values.get(STATS_FROM, 0.0)))
            else:
                self.fmu.doStep(0.0, duration)
            call = "fmi2Get*"
            row.update(self._get(self.metric_real, self.metric_int))
            if record:
                rec = [self.model.outputs[n] for n in record]
                row.update(self._get([v for v in rec if v.type == "Real"],
                                     [v for v in rec if v.type != "Real"]))
            row.update(status="ok", message="")
        except FMICallException as e:
            msgs = [m for s, m in self.logs if s >= 2] or [m for _, m in self.logs]
            label = ("ok", "warning", "discard", "error", "fatal")[min(e.status, 4)]
            row.update(status="refused", message=f"{call} returned {label}"
                       + (f": {msgs[-1]}" if msgs else " (the FMU logged no message)"))
            if e.status >= 4:  # fmi2Fatal: the instance is gone; the next point gets a new one
                raise _Fatal(row) from e
        row["cpu_s"] = time.process_time() - t0
        return row

    def _set(self, values):
        real, ints, bools = [], [], []
        for name, value in values.items():
            v = self.model.parameters[name]
            (real if v.type == "Real" else bools if v.type == "Boolean" else ints).append(
                (v.vr, value))
        if real:
            self.fmu.setReal([vr for vr, _ in real], [float(x) for _, x in real])
        if ints:
            self.fmu.setInteger([vr for vr, _ in ints], [int(x) for _, x in ints])
        if bools:
            self.fmu.setBoolean([vr for vr, _ in bools], [bool(x) for _, x in bools])

    def _get(self, real, ints):
        out = {}
        if real:
            out.update(zip((v.name for v in real), self.fmu.getReal([v.vr for v in real])))
        if ints:
            out.update(zip((v.name for v in ints), self.fmu.getInteger([v.vr for v in ints])))
        return out


class _Fatal(Exception):
    """fmi2Fatal from the FMU: carries the point's row; the instance must be dropped."""

    def __init__(self, row):
        super().__init__(row["message"])
        self.row = row


def instance(guid):
    """This thread's instance of the FMU with this GUID (created on first use)."""
    insts = getattr(_THREAD, "instances", None)
    if insts is None:
        insts = _THREAD.instances = {}
    if guid not in insts:
        if guid not in _FMUS:
            _install_from_plugin(guid)
        insts[guid] = Instance(*_FMUS[guid])
    return insts[guid]


def _install_from_plugin(guid):
    """The FMU from this Dask worker's plugin, should a task start before the plugin's setup."""
    try:
        from distributed import get_worker

        plugin = get_worker().plugins[FMUPlugin.name_of(guid)]
    except (ImportError, ValueError, KeyError):
        raise RuntimeError(f"FMU {guid} is not installed in this process (install_fmu)") from None
    install_fmu(plugin.guid, plugin.data)


def drop_instance(guid):
    insts = getattr(_THREAD, "instances", {})
    inst = insts.pop(guid, None)
    if inst is not None:
        _LOGS.pop(inst.name, None)


class Batch:
    """A batch of points [(point index, point id, {name: value})] with what its rows need: one
    opaque task argument, so that Dask does not walk through its points looking for futures."""

    __slots__ = ("guid", "duration", "record", "schema", "points", "sound")

    def __init__(self, guid, duration, record, schema, points, sound=False):
        self.guid, self.duration, self.record = guid, duration, tuple(record)
        self.schema, self.points, self.sound = schema, points, sound

    def table(self, rows):
        """The points' result rows (metrics and status, in order) completed with each point's
        values and identity, as one Arrow table of the study's schema."""
        import pyarrow as pa

        return pa.Table.from_pylist(
            [{**row, **values, "point": index, "duration": self.duration, "guid": self.guid,
              "point_id": pid} for row, (index, pid, values) in zip(rows, self.points)],
            schema=self.schema)


def run_batch(batch):
    """Run a batch on this thread's instance: its rows as an Arrow table, built here so that the
    client only stores it."""
    rows = []
    for _, _, values in batch.points:
        try:
            row = instance(batch.guid).run(values, batch.duration, batch.record, batch.sound)
        except _Fatal as e:
            drop_instance(batch.guid)
            row = {**e.row, "cpu_s": float("nan")}
        except Exception as e:  # noqa: BLE001 (the instance's state is unknown: a new one)
            drop_instance(batch.guid)
            row = failed(f"{type(e).__name__}: {e}")
        rows.append(row)
    return batch.table(rows)


def failed(message):
    """The row of a point that could not be run (not the FMU's refusal): retried on resume."""
    return {"status": FAILED, "message": message, "cpu_s": float("nan")}


FAILED = "failed"


class FMUPlugin(WorkerPlugin):
    """Installs the FMU on every worker, including workers that join or restart later: the FMU
    travels with the plugin, no shared file system is needed."""

    def __init__(self, guid, data):
        self.guid, self.data = guid, data
        self.name = self.name_of(guid)

    @staticmethod
    def name_of(guid):
        return f"gearrattle-fmu-{guid}"

    def setup(self, worker):
        install_fmu(self.guid, self.data)

    def teardown(self, worker):
        uninstall_fmu(self.guid)
