"""Reading a study's result table (pyarrow, one row per point): the rows that ran and a column
as floats, shared by the summary, the figures and the Monte Carlo analysis."""

import numpy as np


def ok_rows(table):
    return np.asarray(table.column("status").to_pylist()) == "ok"


def column(table, name):
    return np.asarray(table.column(name).to_numpy(zero_copy_only=False), dtype=float)
