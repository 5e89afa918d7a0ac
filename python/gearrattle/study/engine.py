"""Runs a validated study: its points in batches on Dask distributed (a LocalCluster with one
single-threaded worker process per core, or the cluster at --scheduler), or serially in this
process (workers = 0). Completed batches are stored as they arrive; points already stored are
skipped."""

import hashlib
import logging
import math
import os

from . import designs, results
from .model import STATS_FROM
from .worker import FAILED, Batch, FMUPlugin, failed, install_fmu, run_batch
from ..progress import Progress

# The local cluster has no dashboard, so nothing reads its profiler's samples (every 10 ms in
# each worker), the system monitor or the 20-ms event-loop tick: off, so that they take no CPU
# from the points on a machine whose cores the workers fill (docs/DECISIONS.md D30).
QUIET_CLUSTER = {"distributed.worker.profile.enabled": False,
                 "distributed.admin.tick.interval": "1s",
                 "distributed.admin.system-monitor.interval": "1s"}
TASKS_PER_WORKER = 8  # batches per worker: balances the load and bounds what a lost worker costs
BATCH_MAX = 100  # points per batch at most (about 0.3 s of work on one core)
TAIL = 2  # towards the end a batch is at most 1/(TAIL * workers) of the points left ...
TAIL_MIN = 8  # ... and at least 1/TAIL_MIN of the study's batch size


class Plan:
    """The study's points with their full start values, identities and the result columns."""

    def __init__(self, st, model, varied=None):
        self.st, self.model = st, model
        fixed = {n: v for n, (v, _) in st.fixed.items()}
        if st.stats_from is not None:
            fixed[STATS_FROM] = st.stats_from[0]
        varied = designs.points(st) if varied is None else varied
        self.values = [{**p, **fixed} for p in varied]
        names = list(varied[0]) if varied else []
        self.param_names = names + [n for n in fixed if n not in names]
        self.ids = [results.point_id(v, model.guid, st.duration, st.sound) for v in self.values]
        self.schema = results.schema(self.param_names, model, st.record, st.sound)

    def batch(self, points):
        """The points [(index, id, values)] as one batch of this study."""
        return Batch(self.model.guid, self.st.duration, self.st.record, self.schema, points,
                     self.st.sound)


def batch_size(n_points, n_workers):
    return max(1, min(BATCH_MAX, math.ceil(n_points / (TASKS_PER_WORKER * max(n_workers, 1)))))


def batches(todo, n_workers):
    """The points in batches of batch_size; with several workers the batches shrink towards
    the end (guided self-scheduling) so that the workers run out of work together rather than
    one batch apart."""
    n = max(n_workers, 1)
    size = batch_size(len(todo), n)
    out, k = [], 0
    while k < len(todo):
        left = len(todo) - k
        step = size if n == 1 else min(size, max(math.ceil(size / TAIL_MIN),
                                                 math.ceil(left / (TAIL * n))))
        out.append(todo[k:k + step])
        k += step
    return out


def execute(st, model, fmu_bytes, quiet=False, points=None, session=None):
    """Run what is missing of the study; return the consolidated pyarrow table. points: the
    varied values of each point, instead of the study's design; session: an open Session
    (several studies on one cluster), else one is opened for this study."""
    plan = Plan(st, model, points)
    store = results.Store(st.out)
    done = {pid: r for pid, r in store.done().items() if r["status"] != FAILED}
    todo, seen = [], set()
    for i, pid in enumerate(plan.ids):
        if pid not in done and pid not in seen:
            seen.add(pid)
            todo.append((i, pid, plan.values[i]))
    if not quiet and done:
        print(f"gearrattle-study: {len(plan.ids) - len(todo)} of {len(plan.ids)} points already "
              f"in {st.out}: running the other {len(todo)}", flush=True)
    tables = []
    if todo:
        bar = None if quiet else Progress(len(todo), f"{st.kind} study")

        def store_batch(table):
            store.append(table)
            tables.append(table)
            if bar:
                refused = table.num_rows - table["status"].to_pylist().count("ok")
                bar.update(table.num_rows, f"{refused} refused" if refused else "")

        if session is None:
            with Session(st, model, fmu_bytes) as own:
                own.run(plan, todo, store_batch)
        else:
            session.run(plan, todo, store_batch)
        if bar:
            bar.close()
    return store.consolidate(plan.ids, list(done.values()), tables, plan.schema)


def _key(batch):
    return "gearrattle-batch-" + hashlib.sha256("".join(p for _, p, _ in batch.points).encode()
                                                ).hexdigest()[:24]


class Session:
    """Where the points run: this process (workers = 0), a LocalCluster with one
    single-threaded worker process per core (or --workers), or the cluster at --scheduler.
    The FMU is installed on every worker by a plugin, once per session."""

    def __init__(self, st, model, fmu_bytes):
        self.st, self.model, self.data = st, model, fmu_bytes
        self.client = self.cluster = self.plugin = None

    def __enter__(self):
        if self.st.workers == 0:
            install_fmu(self.model.guid, self.data)
            return self
        import dask
        from distributed import Client, LocalCluster

        if self.st.scheduler:
            self.client = Client(self.st.scheduler, timeout="30s")
        else:
            n = self.st.workers or os.cpu_count() or 1
            # no dashboards (no port to find); the study reports its own errors. The scheduler
            # and the workers read QUIET_CLUSTER as they start.
            with dask.config.set(QUIET_CLUSTER):
                self.cluster = LocalCluster(n_workers=n, threads_per_worker=1, processes=True,
                                            dashboard_address=None, worker_dashboard_address=None,
                                            silence_logs=logging.CRITICAL)
            self.client = Client(self.cluster)
        self.plugin = FMUPlugin(self.model.guid, self.data)
        self.client.register_plugin(self.plugin)
        return self

    def __exit__(self, *exc):
        if self.client is not None:
            if exc[0] is None:
                self.client.unregister_worker_plugin(self.plugin.name)
            self.client.close()
        if self.cluster is not None:
            self.cluster.close(timeout=10)

    def workers(self):
        return 1 if self.client is None else max(len(self.client.scheduler_info()["workers"]), 1)

    def run(self, plan, todo, store_batch):
        """Run the points [(index, id, values)] in batches; store_batch(table) as each ends."""
        batched = [plan.batch(b) for b in batches(todo, self.workers())]
        if self.client is None:
            for b in batched:
                store_batch(run_batch(b))
            return
        from distributed import as_completed

        # a batch's key names its points: the same key on a shared cluster is the same work
        futures = {self.client.submit(run_batch, b, pure=False, key=_key(b)): b for b in batched}
        for fut in as_completed(futures):
            try:
                table = fut.result()
            except Exception as e:  # noqa: BLE001 (e.g. KilledWorker: the batch killed its
                # workers again and again); its points are recorded, not dropped
                b = futures[fut]
                table = b.table([failed(f"{type(e).__name__}: {e}")] * len(b.points))
            store_batch(table)
