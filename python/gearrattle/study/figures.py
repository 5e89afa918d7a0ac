"""Figures of the map and DOE studies (PNG): one overview each, a panel per metric, so that the
figures cost a few seconds whatever the number of metrics."""

import os

import numpy as np

from .table import column, ok_rows

COLS = 4


def panels(n, width=4.2, height=3.0):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    rows = -(-n // COLS)
    # a fixed layout: constrained layout takes seconds per dozen colour bars
    fig, axes = plt.subplots(rows, COLS, figsize=(width * COLS, height * rows), squeeze=False)
    h = height * rows  # margins in inches: 0.7 above for the title, 0.55 below for a label
    fig.subplots_adjust(left=0.05, right=0.92, bottom=0.55 / h, top=1 - 0.7 / h, wspace=0.35,
                        hspace=0.6)
    for ax in list(axes.flat)[n:]:
        ax.axis("off")
    return plt, fig, list(axes.flat)[:n]


def save(plt, fig, path):
    fig.savefig(path, dpi=80)
    plt.close(fig)
    return path


def map_figures(st, table, metrics):
    """map_overview.png: a heat map per metric over the grid (blank: refused points)."""
    x, y = st.axes
    xs, ys = x.values(), y.values()
    ok = ok_rows(table)
    ix = np.searchsorted(xs, column(table, x.name))
    iy = np.searchsorted(ys, column(table, y.name))
    plt, fig, axes = panels(len(metrics))
    for ax, m in zip(axes, metrics):
        Z = np.full((len(ys), len(xs)), np.nan)
        Z[iy[ok], ix[ok]] = column(table, m)[ok]
        mesh = ax.pcolormesh(_edges(xs), _edges(ys), np.ma.masked_invalid(Z), shading="flat")
        fig.colorbar(mesh, ax=ax)
        ax.set_title(m, fontsize=9)
        ax.set_xlabel(x.name, fontsize=8)
        ax.set_ylabel(y.name, fontsize=8)
        ax.tick_params(labelsize=7)
    fig.suptitle(f"{st.out}: {table.num_rows} points of {st.duration:g} s", fontsize=10)
    return [save(plt, fig, os.path.join(st.out, "map_overview.png"))]


def _edges(v):
    v = np.asarray(v, dtype=float)
    if len(v) == 1:
        w = max(0.1 * abs(v[0]), 1e-12)
        return np.array([v[0] - w / 2, v[0] + w / 2])
    d = np.diff(v)
    return np.concatenate(([v[0] - d[0] / 2], v[:-1] + d / 2, [v[-1] + d[-1] / 2]))


def doe_figures(st, table, metrics):
    """doe_<parameter>.png: each metric against the parameter, coloured by the next one."""
    ok = ok_rows(table)
    files = []
    for k, r in enumerate(st.ranges):
        other = st.ranges[(k + 1) % len(st.ranges)] if len(st.ranges) > 1 else None
        plt, fig, axes = panels(len(metrics))
        for ax, m in zip(axes, metrics):
            colour = {"c": column(table, other.name)[ok], "cmap": "viridis"} if other else {}
            sc = ax.scatter(column(table, r.name)[ok], column(table, m)[ok], s=6, **colour)
            ax.set_title(m, fontsize=9)
            ax.set_xlabel(r.name, fontsize=8)
            ax.tick_params(labelsize=7)
            ax.grid(alpha=0.3)
        if other:
            fig.colorbar(sc, ax=axes, label=other.name, shrink=0.5, pad=0.01)
        fig.suptitle(f"{st.out}: each metric against {r.name}"
                     + (f", coloured by {other.name}" if other else ""), fontsize=10)
        files.append(save(plt, fig, os.path.join(st.out, f"doe_{r.name}.png")))
    return files
