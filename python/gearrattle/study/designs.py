"""The points of a study: each a {parameter name: value} dict, in a fixed order (the row order
of the results).
    map  the grid x by y (x outer),
    doe  full factorial (n levels per parameter) or a Latin hypercube of n points (scipy.stats.qmc),
    mc   n samples of the tolerances (or Saltelli's / Morris' designs of SALib), repeated at each
         operating point (the same gearboxes at every operating point)."""

import itertools

import numpy as np

from .distributions import U_EDGE

MORRIS_LEVELS = 4
MORRIS_SPAN = (0.005, 0.995)  # Morris' grid spans these quantiles of each distribution


def problem(st):
    """SALib's description of the mc study's inputs, on the unit hypercube (the distributions
    are applied through their quantile functions)."""
    return {"num_vars": len(st.dists), "names": [d.name for d in st.dists],
            "bounds": [[0.0, 1.0]] * len(st.dists)}


def unit_sample(st):
    """The mc study's sample on the unit hypercube: n rows (plain), n (D + 2) rows (Sobol',
    first and total order) or n (D + 1) rows (Morris, n trajectories)."""
    if st.sensitivity == "sobol":
        from SALib.sample import sobol

        return sobol.sample(problem(st), st.n, calc_second_order=False, seed=st.seed)
    if st.sensitivity == "morris":
        from SALib.sample import morris

        u = morris.sample(problem(st), st.n, num_levels=MORRIS_LEVELS, seed=st.seed)
        return MORRIS_SPAN[0] + (MORRIS_SPAN[1] - MORRIS_SPAN[0]) * u
    return np.random.default_rng(st.seed).random((st.n, len(st.dists)))


def mc_sample(st):
    """The mc study's tolerance values: an array of shape (rows, D)."""
    u = np.clip(unit_sample(st), U_EDGE, 1 - U_EDGE)
    return np.column_stack([d.ppf(u[:, j]) for j, d in enumerate(st.dists)])


def points(st):
    """[{name: value}] of the varied parameters (and the operating point), in row order."""
    if st.kind == "map":
        x, y = st.axes
        return [{x.name: a, y.name: b} for a in x.values() for b in y.values()]
    if st.kind == "doe":
        if st.design == "full":
            levels = [np.linspace(r.lo, r.hi, st.n) for r in st.ranges]
            grid = itertools.product(*levels)
        else:
            from scipy.stats import qmc

            u = qmc.LatinHypercube(d=len(st.ranges), seed=st.seed).random(st.n)
            grid = qmc.scale(u, [r.lo for r in st.ranges], [r.hi for r in st.ranges])
        return [{r.name: float(v) for r, v in zip(st.ranges, row)} for row in grid]
    sample = mc_sample(st)
    ops = [p for p, _ in st.at] or [{}]
    return [{**op, **{d.name: float(v) for d, v in zip(st.dists, row)}}
            for op in ops for row in sample]
