"""Figures of the map and DOE studies (PNG)."""

import os

import numpy as np

from .report import column, ok_rows


def _plt():
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def map_figures(st, table, metrics):
    """One heat map per metric: map_<metric>.png."""
    plt = _plt()
    x, y = st.axes
    xs, ys = x.values(), y.values()
    ok = ok_rows(table)
    X, Y = column(table, x.name), column(table, y.name)
    files = []
    for m in metrics:
        Z = np.full((len(ys), len(xs)), np.nan)
        for xv, yv, z, good in zip(X, Y, column(table, m), ok):
            if good:
                Z[ys.index(yv), xs.index(xv)] = z
        fig, ax = plt.subplots(figsize=(8, 5.5), constrained_layout=True)
        mesh = ax.pcolormesh(_edges(xs), _edges(ys), np.ma.masked_invalid(Z), shading="flat")
        fig.colorbar(mesh, ax=ax, label=m)
        ax.set_xlabel(x.name)
        ax.set_ylabel(y.name)
        ax.set_title(f"{m} ({st.duration:g} s per point; white: refused)")
        path = os.path.join(st.out, f"map_{m}.png")
        fig.savefig(path, dpi=90)
        plt.close(fig)
        files.append(path)
    return files


def _edges(v):
    v = np.asarray(v, dtype=float)
    if len(v) == 1:
        w = max(0.1 * abs(v[0]), 1e-12)
        return np.array([v[0] - w / 2, v[0] + w / 2])
    d = np.diff(v)
    return np.concatenate(([v[0] - d[0] / 2], v[:-1] + d / 2, [v[-1] + d[-1] / 2]))


def doe_figures(st, table, metrics):
    """Each metric against each varied parameter: doe_<metric>.png."""
    plt = _plt()
    ok = ok_rows(table)
    files = []
    for m in metrics:
        z = column(table, m)
        fig, axes = plt.subplots(1, len(st.ranges), figsize=(4 * len(st.ranges), 3.5),
                                 squeeze=False, constrained_layout=True)
        for ax, r in zip(axes[0], st.ranges):
            ax.plot(column(table, r.name)[ok], z[ok], ".", ms=4)
            ax.set_xlabel(r.name)
            ax.set_ylabel(m)
            ax.grid(alpha=0.3)
        path = os.path.join(st.out, f"doe_{m}.png")
        fig.savefig(path, dpi=90)
        plt.close(fig)
        files.append(path)
    return files
