"""Figures of the map and DOE studies (PNG): one overview each, a panel per metric that varies
over the study, so that the figures cost a few seconds whatever the number of metrics; and for
a gearbox, the map of which gear rattles where. Titles in words, units on every axis and colour
bar (gearrattle.study.labels)."""

import os

import numpy as np

from .labels import axis, phrase, words
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


def varies(table, name):
    """Whether a metric takes more than one value over the study's points (a constant one gets
    no panel: it says nothing about where the metric changes)."""
    x = column(table, name)[ok_rows(table)]
    x = x[np.isfinite(x)]
    return len(x) > 1 and x.min() != x.max()


def _grid(st, table, name):
    """The metric on the map's grid (NaN: refused points), with the cell edges."""
    x, y = st.axes
    xs, ys = x.values(), y.values()
    ok = ok_rows(table)
    ix = np.searchsorted(xs, column(table, x.name))
    iy = np.searchsorted(ys, column(table, y.name))
    Z = np.full((len(ys), len(xs)), np.nan)
    Z[iy[ok], ix[ok]] = column(table, name)[ok]
    return _edges(xs), _edges(ys), Z


def _label_axes(ax, model, x, y):
    ax.set_xlabel(axis(model, x), fontsize=8)
    ax.set_ylabel(axis(model, y), fontsize=8)
    ax.tick_params(labelsize=7)


def map_figure(st, model, table, metrics):
    """The overview's figure (matplotlib objects, not saved): a heat map per metric over the
    grid, blank where the FMU refused a point."""
    x, y = st.axes
    plt, fig, axes = panels(len(metrics))
    for ax, m in zip(axes, metrics):
        X, Y, Z = _grid(st, table, m)
        mesh = ax.pcolormesh(X, Y, np.ma.masked_invalid(Z), shading="flat")
        fig.colorbar(mesh, ax=ax).set_label(axis(model, m), fontsize=8)
        ax.set_title(words(model, m), fontsize=9)
        _label_axes(ax, model, x.name, y.name)
    fig.suptitle(f"Rattle map over {phrase(model, x.name)} and "
                 f"{phrase(model, y.name)}: {table.num_rows} points of "
                 f"{st.duration:g} s each", fontsize=10)
    return plt, fig


def gear_figure(st, model, table, gears, metric="stat_rattle_power"):
    """Which gear rattles where (matplotlib objects, not saved): one heat map per gear of its
    `gear[i].<metric>` and one of the box's `<metric>`, on one logarithmic colour scale so that
    the panels compare; grey where the gear has no impact, blank where the FMU refused."""
    from matplotlib.colors import LogNorm

    x, y = st.axes
    names = [f"gear[{i}].{metric}" for i in gears] + [metric]
    grids = [_grid(st, table, n) for n in names]
    values = np.concatenate([Z[np.isfinite(Z)].ravel() for _, _, Z in grids])
    top = values.max() if values.size and values.max() > 0 else 1.0
    norm = LogNorm(vmin=top * 1e-4, vmax=top)
    plt, fig, axes = panels(len(names))
    for ax, n, (X, Y, Z) in zip(axes, names, grids):
        cmap = plt.get_cmap("magma").with_extremes(under="0.85")
        mesh = ax.pcolormesh(X, Y, np.ma.masked_invalid(np.where(Z > 0, Z, top * 1e-6)),
                             shading="flat", norm=norm, cmap=cmap)
        ax.set_title(f"gear {n[5:n.index(']')]}" if n != metric else "the box (all gears)",
                     fontsize=9)
        _label_axes(ax, model, x.name, y.name)
    fig.colorbar(mesh, ax=axes, shrink=0.8, pad=0.02).set_label(axis(model, metric), fontsize=9)
    what = words(model, f"gear[{gears[0]}].{metric}").split(": ", 1)[-1].lower()
    fig.suptitle(f"Which gear rattles where: {what} of each gear and of the box over "
                 f"{phrase(model, x.name)} and {phrase(model, y.name)} "
                 f"(grey: no impact)", fontsize=10)
    return plt, fig


def map_figures(st, model, table, metrics, gears=()):
    """map_overview.png, and for a gearbox map_gears.png (gear_figure)."""
    files = [save(*map_figure(st, model, table, metrics),
                  os.path.join(st.out, "map_overview.png"))] if metrics else []
    if gears:
        files.append(save(*gear_figure(st, model, table, gears),
                          os.path.join(st.out, "map_gears.png")))
    return files


def _edges(v):
    v = np.asarray(v, dtype=float)
    if len(v) == 1:
        w = max(0.1 * abs(v[0]), 1e-12)
        return np.array([v[0] - w / 2, v[0] + w / 2])
    d = np.diff(v)
    return np.concatenate(([v[0] - d[0] / 2], v[:-1] + d / 2, [v[-1] + d[-1] / 2]))


def doe_figures(st, model, table, metrics):
    """doe_<parameter>.png: each metric against the parameter, coloured by the next one."""
    ok = ok_rows(table)
    files = []
    for k, r in enumerate(st.ranges):
        other = st.ranges[(k + 1) % len(st.ranges)] if len(st.ranges) > 1 else None
        plt, fig, axes = panels(len(metrics))
        for ax, m in zip(axes, metrics):
            colour = {"c": column(table, other.name)[ok], "cmap": "viridis"} if other else {}
            sc = ax.scatter(column(table, r.name)[ok], column(table, m)[ok], s=6, **colour)
            ax.set_title(words(model, m), fontsize=9)
            ax.set_xlabel(axis(model, r.name), fontsize=8)
            ax.set_ylabel(axis(model, m), fontsize=8)
            ax.tick_params(labelsize=7)
            ax.grid(alpha=0.3)
        if other:
            fig.colorbar(sc, ax=axes, label=axis(model, other.name), shrink=0.5, pad=0.01)
        fig.suptitle(f"Each metric against {phrase(model, r.name)} ({r.name})"
                     + (f", coloured by {other.name}" if other else ""), fontsize=10)
        files.append(save(plt, fig, os.path.join(st.out, f"doe_{r.name}.png")))
    return files
