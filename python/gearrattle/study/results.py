"""The results of a study on disk: each completed batch appended as one Parquet file in
DIR/partial/ (so an interrupted study loses nothing), the whole study consolidated into
DIR/points.parquet and DIR/points.csv, one row per point in design order.

A point is identified by a hash of its parameter values, the FMU's GUID, the duration and
stats_from: a restarted study (or a larger one in the same directory) skips the points whose
rows are already there."""

import hashlib
import json
import os
import uuid

STATUS_COLUMNS = ["status", "message", "cpu_s", "guid"]


def point_id(values, guid, duration, sound=False):
    """Hex digest of the point's identity. values includes stats_from when the FMU has it; a
    point with the sound columns is another point than the same without."""
    key = [guid, float(duration).hex(), sorted((k, float(v).hex()) for k, v in values.items())]
    if sound:
        key.append("sound")
    return hashlib.sha256(json.dumps(key).encode()).hexdigest()[:24]


class Store:
    def __init__(self, out):
        self.out = out
        self.partial = os.path.join(out, "partial")
        os.makedirs(self.partial, exist_ok=True)

    def done(self):
        """{point id: row} of every point already computed in this directory."""
        import pyarrow.parquet as pq

        rows = {}
        for name in sorted(os.listdir(self.partial)):
            if name.endswith(".parquet"):
                for r in pq.read_table(os.path.join(self.partial, name)).to_pylist():
                    if rows.get(r["point_id"], {}).get("status") in (None, "failed"):
                        rows[r["point_id"]] = r  # a point run again after failing
        return rows

    def append(self, table):
        """Write a batch's table as one new file (atomically: a crash leaves no half file)."""
        import pyarrow.parquet as pq

        path = os.path.join(self.partial, f"{uuid.uuid4().hex}.parquet")
        pq.write_table(table, path + ".tmp")
        os.replace(path + ".tmp", path)

    def consolidate(self, ids, done, tables, schema):
        """points.parquet and points.csv: for each point id of the design in order, its row from
        the rows already stored (done) or from the tables computed now."""
        import pyarrow as pa
        import pyarrow.csv as pcsv
        import pyarrow.parquet as pq

        every = pa.concat_tables([pa.Table.from_pylist(done, schema=schema), *tables])
        at = {pid: k for k, pid in enumerate(every["point_id"].to_pylist())}
        table = every.take([at[pid] for pid in ids])
        # a stored point may sit at another index in this design
        table = table.set_column(0, "point", pa.array(range(len(ids)), pa.int64()))
        pq.write_table(table, os.path.join(self.out, "points.parquet"))
        pcsv.write_csv(table, os.path.join(self.out, "points.csv"))
        return table


def schema(param_names, model, record, sound=False):
    """Columns: point, the parameters (FMU names), duration, the metrics (stat_*), the recorded
    outputs, the sound columns (with --sound), status, message, cpu_s, guid, point_id."""
    from ..sound.study import COLUMNS, COST

    import pyarrow as pa

    def arrow(var):
        return pa.float64() if var.type == "Real" else pa.int64()

    fields = [pa.field("point", pa.int64())]
    fields += [pa.field(n, arrow(model.parameters[n])) for n in param_names]
    fields += [pa.field("duration", pa.float64())]
    fields += [pa.field(v.name, arrow(v)) for v in model.metrics]
    fields += [pa.field(n, arrow(model.outputs[n])) for n in record]
    fields += [pa.field(n, pa.float64()) for n in (*COLUMNS, COST)] if sound else []
    fields += [pa.field("status", pa.string()), pa.field("message", pa.string()),
               pa.field("cpu_s", pa.float64()), pa.field("guid", pa.string()),
               pa.field("point_id", pa.string())]
    return pa.schema(fields)
