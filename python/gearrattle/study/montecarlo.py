"""The Monte Carlo study's answers, per operating point: the distribution of each metric
(percentiles; histogram and ECDF figures), the probability of exceeding each user threshold
with its 95 % Clopper-Pearson interval, and Sobol' (Saltelli) or Morris sensitivity indices
(SALib). Written to percentiles.csv, exceedance.csv, sensitivity.csv and mc_*.png."""

import csv
import os

import numpy as np

from . import designs
from .figures import panels, save
from .labels import axis, words
from .table import column, ok_rows

PERCENTILES = (1, 5, 25, 50, 75, 95, 99)
CONFIDENCE = 0.95


def _operating_points(st, table):
    """[(label, row mask)]: one per --at operating point (all rows when there is none)."""
    if not st.at:
        return [("", np.ones(table.num_rows, bool))]
    out = []
    for point, _ in st.at:
        mask = np.ones(table.num_rows, bool)
        for name, value in point.items():
            mask &= column(table, name) == value
        out.append((", ".join(f"{k} = {v:g}" for k, v in point.items()), mask))
    return out


def exceedance(k, n, confidence=CONFIDENCE):
    """(k/n, low, high): the share and its Clopper-Pearson (exact binomial) interval."""
    from scipy.stats import binomtest

    if n == 0:
        return float("nan"), float("nan"), float("nan")
    ci = binomtest(k, n).proportion_ci(confidence_level=confidence, method="exact")
    return k / n, ci.low, ci.high


def analyse(st, model, table, metrics, drawn):
    """Summary lines and files; every metric in the CSVs, those in drawn in the figures."""
    ok = ok_rows(table)
    lines, files, pct_rows, exc_rows, sens_rows = [], [], [], [], []
    for label, mask in _operating_points(st, table):
        sel = mask & ok
        head = f"at {label}" if label else "over the sample"
        lines.append(f"Monte Carlo {head}: {int(sel.sum())} of {int(mask.sum())} points ok")
        for m in metrics:  # a metric undefined at a point (a mean over no impact) is left out
            x = column(table, m)[sel]
            x = x[np.isfinite(x)]
            if len(x):
                q = np.percentile(x, PERCENTILES)
                pct_rows.append([label, m, len(x), np.mean(x), np.std(x, ddof=1) if len(x) > 1
                                 else float("nan"), *q])
        for e in st.exceed:
            x = column(table, e.metric)[sel]
            k = int(np.count_nonzero(e.test(x)))
            p, lo, hi = exceedance(k, len(x))
            exc_rows.append([label, str(e), k, len(x), p, lo, hi])
            lines.append(f"  P({e}) = {k}/{len(x)} = {100 * p:.1f} % ({100 * CONFIDENCE:g} % "
                         f"Clopper-Pearson interval {100 * lo:.1f}..{100 * hi:.1f} %)")
        if st.sensitivity != "none":
            more, rows = _sensitivity(st, table, mask, metrics, label)
            lines += more
            sens_rows += rows
        if drawn:
            files.append(_figure(st, model, table, sel, drawn, label, len(files)))
    files.append(_csv(st.out, "percentiles.csv", ["operating_point", "metric", "n", "mean", "sd"]
                      + [f"p{p}" for p in PERCENTILES], pct_rows))
    if exc_rows:
        files.append(_csv(st.out, "exceedance.csv", ["operating_point", "event", "k", "n", "p",
                                                     "ci_low", "ci_high"], exc_rows))
    drawn_rows = [r for r in sens_rows if r[1] in drawn]
    if sens_rows:
        cols = (["operating_point", "metric", "parameter", "S1", "S1_conf", "ST", "ST_conf"]
                if st.sensitivity == "sobol" else
                ["operating_point", "metric", "parameter", "mu_star", "mu_star_conf", "sigma"])
        files.append(_csv(st.out, "sensitivity.csv", cols, sens_rows))
        if drawn_rows:
            files.append(_sensitivity_figure(st, model, drawn_rows))
    return lines, files


def _sensitivity(st, table, mask, metrics, label):
    """Indices of each metric over the design's rows at one operating point. Needs every row:
    a refused point leaves the design incomplete, and the indices are not computed."""
    lines, rows = [], []
    ok = ok_rows(table)[mask]
    if not ok.all():
        return [f"  sensitivity not computed: {int((~ok).sum())} points refused (see "
                f"points.csv)"], []
    prob = designs.problem(st)
    names = prob["names"]
    for m in metrics:
        y = column(table, m)[mask]
        if not np.isfinite(y).all() or np.ptp(y) == 0:
            continue  # undefined somewhere, or constant: no variance to apportion
        if st.sensitivity == "sobol":
            from SALib.analyze import sobol

            r = sobol.analyze(prob, y, calc_second_order=False, seed=st.seed)
            rows += [[label, m, p, r["S1"][i], r["S1_conf"][i], r["ST"][i], r["ST_conf"][i]]
                     for i, p in enumerate(names)]
        else:
            from SALib.analyze import morris

            x = designs.unit_sample(st)
            r = morris.analyze(prob, x, y, num_levels=designs.MORRIS_LEVELS, seed=st.seed)
            rows += [[label, m, p, r["mu_star"][i], r["mu_star_conf"][i], r["sigma"][i]]
                     for i, p in enumerate(names)]
    lines.append(f"  {st.sensitivity} indices of {len({r[1] for r in rows})} metrics: "
                 f"sensitivity.csv, mc_sensitivity.png")
    return lines, rows


def _csv(out, name, header, rows):
    path = os.path.join(out, name)
    with open(path, "w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(header)
        w.writerows([f"{v:.6g}" if isinstance(v, float) else v for v in r] for r in rows)
    return path


def _figure(st, model, table, sel, metrics, label, k):
    """Histogram and ECDF of each metric: mc_distributions[_k].png."""
    plt, fig, axes = panels(len(metrics))
    for ax, m in zip(axes, metrics):
        x = column(table, m)[sel]
        x = np.sort(x[np.isfinite(x)])
        ax.hist(x, bins=min(40, max(5, len(x) // 20)), color="tab:blue", alpha=0.6)
        ax.set_title(words(model, m), fontsize=9)
        ax.set_xlabel(axis(model, m), fontsize=8)
        ax.set_ylabel("gearboxes", fontsize=8)
        ax.tick_params(labelsize=7)
        e = ax.twinx()
        e.set_ylabel("share at or below", fontsize=8)
        e.plot(x, np.arange(1, len(x) + 1) / len(x), color="k", lw=1)
        e.set_ylim(0, 1)
        e.tick_params(labelsize=7)
        for ex in st.exceed:
            if ex.metric == m:
                ax.axvline(ex.value, color="tab:red", ls="--", lw=1)
    dists = "; ".join(str(d) for d in st.dists)
    fig.suptitle(f"Monte Carlo{' at ' + label if label else ''}: {int(sel.sum())} gearboxes "
                 f"({dists}); bars histogram, line ECDF, dashed thresholds", fontsize=9)
    name = f"mc_distributions{'_' + str(k) if k else ''}.png"
    return save(plt, fig, os.path.join(st.out, name))


def _sensitivity_figure(st, model, rows):
    """Bars of the indices (S1 and ST, or mu*) per parameter for each metric and operating
    point: mc_sensitivity.png."""
    keys = sorted({(r[0], r[1]) for r in rows})
    names = [d.name for d in st.dists]
    plt, fig, axes = panels(len(keys))
    x = np.arange(len(names))
    for ax, key in zip(axes, keys):
        sel = {r[2]: r for r in rows if (r[0], r[1]) == key}
        if st.sensitivity == "sobol":
            ax.bar(x - 0.2, [sel[n][3] for n in names], 0.4, yerr=[sel[n][4] for n in names],
                   label="S1")
            ax.bar(x + 0.2, [sel[n][5] for n in names], 0.4, yerr=[sel[n][6] for n in names],
                   label="ST")
        else:
            ax.bar(x, [sel[n][3] for n in names], 0.6, yerr=[sel[n][4] for n in names],
                   label="mu*")
        ax.set_xticks(x)
        ax.set_xticklabels(names, fontsize=7)
        ax.set_title(words(model, key[1]) + (f" at {key[0]}" if key[0] else ""), fontsize=8)
        ax.tick_params(labelsize=7)
    axes[0].legend(fontsize=7)
    fig.suptitle(f"{'Sobol' if st.sensitivity == 'sobol' else 'Morris'} indices "
                 f"({st.n} base samples)", fontsize=9)
    return save(plt, fig, os.path.join(st.out, "mc_sensitivity.png"))
