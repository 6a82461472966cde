#!/usr/bin/python3
"""Would a surrogate model rank a CMA-ES generation of the calibration objective?
(offline/calib/MEASUREMENTS.md, session 79)

Surrogate-assisted CMA-ES (lq-CMA-ES, Hansen 2019; GP-based DTS-CMA-ES, Bajer et al. 2019) skips
simulating a generation's candidates when a model fitted to earlier evaluations ranks them as the
true objective does: lq-CMA-ES trusts its model once Kendall's tau between the model's and the
true values of the candidates it did evaluate reaches 0.85. Until then it evaluates more, up to
all of them. So the saving of such a search is bounded by how well a model ranks a generation.

This reads the points of `bench_calib_landscape --points` (one scale: a generation drawn
N(x_file, (s * box)^2), as CMA-ES draws before its covariance has learnt anything) and, per
scale, in folds of one generation (32 points held out, the rest to fit on), ranks the held-out
points with each model and prints Kendall's tau against the simulated combined L, how many of the
true best 16 (CMA-ES's mu) the model's best 16 hold (8 by chance), and tau among the model's best
16 (the ones lq-CMA-ES evaluates first). The combined L is the file's L_combined column: what the
calibration's search minimised (its "combine": sum, worst, bar or count of the sequences' L;
calibration.h, SequenceCombine). Models, all on log L unless named:
  linear, diagonal quadratic, full quadratic (ridge chosen on the fitting points alone), the full
  quadratic on L itself (as lq-CMA-ES fits), one full quadratic per sequence, combined by the
  file's rule (the sequences' landscapes differ) and a Gaussian process (squared-exponential
  kernel, length scale and nugget chosen on the fitting points alone). The points file does not
  name its rule: it is the one of the four whose combination of the L_ columns is L_combined on
  every row (where two agree on every row, e.g. bar and count with no L over 0.3, the first);
  where none is, the per-sequence model is left out.

usage: surrogate_rank.py POINTS.csv [OUT.png] [--low-fidelity LOW.csv]
                                                   the table, and with OUT.png a picture;
                                                   LOW.csv: the same points on a cheaper
                                                   simulator (the calibration file copied with
                                                   "gown": "coarse"), its L as a model
       surrogate_rank.py --self-test               known objectives: a quadratic must be ranked
                                                   (tau >= 0.9), noise must not (|tau| < 0.3);
                                                   points files combined by worst and by max:
                                                   the combined L printed is L_combined's;
                                                   exit 1 if one is not
"""
import contextlib
import io
import itertools
import os
import sys
import tempfile

import numpy as np
from figure_file import save_figure  # a temporary file, then a rename

GENERATION = 32  # the paper's population
MU = 16
TRUST = 0.85  # lq-CMA-ES's threshold on Kendall's tau
RHO, BAR = 0.1, 0.3  # calibration.h: kWorstRho, kSequenceBar


def combine(Ls, rule):
    """combined_objective (offline/calib/calibration.cpp) of each row of per-sequence L (n x K)
    under the rule (calibration.h, SequenceCombine); a row with a non-finite L is infinite."""
    Ls = np.asarray(Ls, dtype=float)
    s = Ls.sum(1)
    excess = np.maximum(0.0, Ls - BAR).sum(1)
    f = {"sum": lambda: s, "worst": lambda: Ls.max(1) + RHO * s, "bar": lambda: excess + RHO * s,
         "count": lambda: (Ls > BAR).sum(1) + (excess + RHO * s)}[rule]()
    return np.where(np.isfinite(Ls).all(1), f, np.inf)


RULES = ("sum", "worst", "bar", "count")


def combine_rule(Ls, y):
    """The rules whose combination of the rows' L (n x K) is y, the file's L_combined, on every row."""
    return [r for r in RULES if np.allclose(combine(Ls, r), y, rtol=1e-12, atol=0)]


def kendall_tau(a, b):
    """Kendall's tau-a of two equal-length sequences (ties count as neither)."""
    a, b = np.asarray(a), np.asarray(b)
    s = np.sign(a[:, None] - a[None, :]) * np.sign(b[:, None] - b[None, :])
    n = len(a)
    return np.triu(s, 1).sum() / (n * (n - 1) / 2)


def features(X, kind):
    cols = [np.ones(len(X))] + list(X.T)
    if kind in ("diag", "full"):
        cols += [x**2 for x in X.T]
    if kind == "full":
        cols += [X[:, i] * X[:, j] for i, j in itertools.combinations(range(X.shape[1]), 2)]
    return np.stack(cols, 1)


def ridge_fit(Xtr, ytr, Xte, kind, ridge):
    A, B = features(Xtr, kind), features(Xte, kind)
    mu, sd = A[:, 1:].mean(0), A[:, 1:].std(0) + 1e-300
    A[:, 1:] = (A[:, 1:] - mu) / sd
    B[:, 1:] = (B[:, 1:] - mu) / sd
    R = ridge * np.eye(A.shape[1])
    R[0, 0] = 0  # the constant is not shrunk
    return B @ np.linalg.lstsq(A.T @ A + R, A.T @ ytr, rcond=None)[0]


def inner_folds(n, k=3):
    idx = np.arange(n)
    return [(np.setdiff1d(idx, f), f) for f in np.array_split(idx, k)]


def quadratic(Xtr, ytr, Xte, kind):
    """Ridge-regressed polynomial, the ridge picked by a 3-fold error on the fitting points."""
    best = min((sum(((ridge_fit(Xtr[a], ytr[a], Xtr[b], kind, r) - ytr[b]) ** 2).sum()
                    for a, b in inner_folds(len(ytr))), r) for r in (1e-6, 0.1, 1.0, 10.0, 100.0))
    return ridge_fit(Xtr, ytr, Xte, kind, best[1])


def gp_predict(Xtr, ytr, Xte, ell, nugget):
    m, s = ytr.mean(), ytr.std() + 1e-300
    d2 = lambda A, B: ((A[:, None, :] - B[None, :, :]) ** 2).sum(-1)
    K = np.exp(-0.5 * d2(Xtr, Xtr) / ell**2) + nugget * np.eye(len(Xtr))
    return m + s * (np.exp(-0.5 * d2(Xte, Xtr) / ell**2) @ np.linalg.solve(K, (ytr - m) / s))


def gaussian_process(Xtr, ytr, Xte):
    best = min((sum(((gp_predict(Xtr[a], ytr[a], Xtr[b], ell, g) - ytr[b]) ** 2).sum()
                    for a, b in inner_folds(len(ytr))), ell, g)
               for ell in (0.5, 1, 2, 3, 5, 8) for g in (1e-4, 1e-2, 0.1, 0.3, 1.0))
    return gp_predict(Xtr, ytr, Xte, best[1], best[2])


# name -> predict(X_fit, per-sequence L of the fit rows (n x K), their combined L, X_held, the
# file's rule) -> predicted combined L (any monotone transform of it: only the ranking counts)
PER_SEQUENCE = "full quadratic per sequence"
MODELS = {
    "linear": lambda X, Ls, y, Xt, rule: quadratic(X, np.log(y), Xt, "lin"),
    "diagonal quadratic": lambda X, Ls, y, Xt, rule: quadratic(X, np.log(y), Xt, "diag"),
    "full quadratic": lambda X, Ls, y, Xt, rule: quadratic(X, np.log(y), Xt, "full"),
    "full quadratic on L": lambda X, Ls, y, Xt, rule: quadratic(X, y, Xt, "full"),
    PER_SEQUENCE: lambda X, Ls, y, Xt, rule: combine(
        np.stack([np.exp(quadratic(X, np.log(Ls[:, k]), Xt, "full")) for k in range(Ls.shape[1])], 1), rule),
    "Gaussian process": lambda X, Ls, y, Xt, rule: gaussian_process(X, np.log(y), Xt),
}


LOW_FIDELITY = "low fidelity (its own L)"


def rank_scale(X, Ls, y, rule, low=None):
    """Per model: (tau per fold, best-16 overlap per fold, tau among the model's best 16 per fold),
    and the held-out predictions of every fold for the picture. y: the combined L of each point
    (the file's L_combined), what every model ranks against; rule: how it combines Ls (None: no
    rule known, the per-sequence model is left out). `low`: the combined L of the same points from
    another simulator (a coarser gown), ranked as it is, with no fitting."""
    n = len(y)
    folds = n // GENERATION
    out = {}
    models = {name: m for name, m in MODELS.items() if rule is not None or name != PER_SEQUENCE}
    if low is not None:
        models[LOW_FIDELITY] = None
    for name, model in models.items():
        taus, overlaps, taus_best, pairs = [], [], [], []
        for f in range(folds):
            held = np.arange(f * GENERATION, (f + 1) * GENERATION)
            fit = np.setdiff1d(np.arange(n), held)
            p = low[held] if model is None else model(X[fit], Ls[fit], y[fit], X[held], rule)
            best = np.argsort(p)[:MU]
            taus.append(kendall_tau(p, y[held]))
            overlaps.append(len(set(best) & set(np.argsort(y[held])[:MU])))
            taus_best.append(kendall_tau(p[best], y[held][best]))
            pairs.append((p, y[held]))
        out[name] = (np.array(taus), np.array(overlaps), np.array(taus_best), pairs)
    return out


def read_points(path):
    """{scale: (steps in units of the scale, per-sequence L, combined L)} and the file's combine
    rule (None when no rule of combined_objective gives its L_combined)."""
    data = np.genfromtxt(path, delimiter=",", names=True)
    names = data.dtype.names
    steps = [c for c in names if c.startswith("d_")]
    seqs = [c for c in names if c.startswith("L_") and c != "L_combined"]
    if not steps or not seqs or "scale" not in names or "L_combined" not in names:
        raise SystemExit(f"{path}: not a bench_calib_landscape --points file (columns {names})")
    all_Ls = np.stack([data[c] for c in seqs], 1)
    rules = combine_rule(all_Ls, data["L_combined"])
    by_scale = {}
    for s in sorted(set(data["scale"]) - {0.0}, reverse=True):
        rows = data[data["scale"] == s]
        if len(rows) < 2 * GENERATION:
            raise SystemExit(f"{path}: scale {s} has {len(rows)} points; need at least {2 * GENERATION}")
        X = np.stack([rows[c] for c in steps], 1) / s  # each step in units of the scale: N(0, 1)
        by_scale[s] = (X, np.stack([rows[c] for c in seqs], 1), rows["L_combined"])
    if not rules:
        print(f"{path}: L_combined is none of {', '.join(RULES)} of the L_ columns: "
              f"'{PER_SEQUENCE}' is left out")
    else:
        print(f"{path}: combined by {' or '.join(rules)} (the rule that gives L_combined"
              f"{', the same on these points' if len(rules) > 1 else ''})")
    return by_scale, (rules[0] if rules else None)


def report(by_scale, rule, low_by_scale=None):
    results = {}
    print(f"{'scale':>6}  {'model':28s} {'tau: min / median / max':>24}  {'best 16 held':>12}"
          f"  {'tau in model best 16':>20}")
    for s, (X, Ls, y) in by_scale.items():
        print(f"{s:6g}  {len(y)} points, combined L min {y.min():.3f} median {np.median(y):.3f} max {y.max():.3f}")
        low = None
        if low_by_scale is not None:
            if s not in low_by_scale or not np.array_equal(low_by_scale[s][0], X):
                raise SystemExit(f"--low-fidelity: its points at scale {s} are not this file's (the same "
                                 "calibration's values, --scales, --samples and --seed draw the same points)")
            low = low_by_scale[s][2]  # its own combined L
        results[s] = rank_scale(X, Ls, y, rule, low)
        for name, (t, o, tb, _) in results[s].items():
            print(f"{'':6}  {name:28s} {t.min():7.3f} / {np.median(t):6.3f} / {t.max():6.3f}"
                  f"  {np.median(o):8.1f} / {MU}  {np.median(tb):20.3f}")
    best = max(np.median(t) for r in results.values() for t, *_ in r.values())
    print(f"\nthe highest median tau of any model at any scale: {best:.3f} "
          f"(lq-CMA-ES trusts a model from {TRUST})")
    return results


def plot(results, out):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    scales = list(results)
    fig, axes = plt.subplots(2, len(scales), figsize=(4 * len(scales), 7.5), squeeze=False)
    for j, s in enumerate(scales):
        ax = axes[0][j]
        names = list(results[s])
        for i, name in enumerate(names):
            t = results[s][name][0]
            ax.plot([i] * len(t), t, "o", color="C0", alpha=0.6)
            ax.plot(i, np.median(t), "_", color="k", markersize=18)
        ax.axhline(TRUST, color="C3", ls="--", label=f"lq-CMA-ES trusts from {TRUST}")
        ax.axhline(0, color="0.6", lw=0.8)
        ax.set_xticks(range(len(names)), [n.replace(" ", "\n", 1) for n in names], fontsize=7, rotation=60)
        ax.set_ylim(-0.4, 1.05)
        ax.set_title(f"step {s:g} of each box: Kendall tau per fold")
        if j == 0:
            ax.set_ylabel("tau, model vs simulated (32 held out)")
            ax.legend(fontsize=8, loc="lower left")
        ax = axes[1][j]
        name = max(results[s], key=lambda k: np.median(results[s][k][0]))
        for p, y in results[s][name][3]:
            ax.plot(np.argsort(np.argsort(p)) + 1, np.argsort(np.argsort(y)) + 1, ".", alpha=0.7)
        ax.plot([1, GENERATION], [1, GENERATION], color="0.5", lw=0.8)
        ax.set_xlabel(f"rank by the model ({name})", fontsize=8)
        if j == 0:
            ax.set_ylabel("rank by the simulator (1 = best)")
        ax.set_title("its held-out generations, one colour each", fontsize=9)
    fig.suptitle("Can a surrogate rank a CMA-ES generation of the calibration objective?")
    fig.tight_layout()
    save_figure(fig, out, dpi=110)
    print(f"wrote {out}")


def self_test():
    """Known objectives, drawn as the bench draws (N(0, 1) steps): a quadratic bowl seen from off its
    minimum is ranked by the quadratic on L (tau >= 0.9); exp of a bowl, by the quadratics on log L
    (tau >= 0.9) and, smooth as it is, by the Gaussian process well above chance (tau >= 0.8);
    independent noise by no model (|median tau| < 0.3). A low fidelity that is a monotone map of
    the bowl ranks it exactly; one that is noise does not. Then points files (points_file_case)."""
    rng = np.random.default_rng(1)
    P, n = 10, 4 * GENERATION
    X = rng.normal(size=(n, P))
    H = rng.normal(size=(P, P))
    H = H @ H.T / P + np.eye(P)
    c = rng.normal(size=P)
    bowl = np.einsum("ni,ij,nj->n", X - c, H, X - c)[:, None] + 0.1
    cases = (
        ("quadratic bowl", bowl, {"full quadratic on L": 0.9}),
        ("exp of a bowl", np.exp(0.05 * bowl),
         {"full quadratic": 0.9, "full quadratic per sequence": 0.9, "Gaussian process": 0.8}),
        ("noise", rng.uniform(0.5, 1.5, size=(n, 1)), {name: None for name in MODELS}),
    )
    ok = True
    lows = {"quadratic bowl": 2 * bowl[:, 0] + 1, "noise": rng.uniform(size=n)}  # a monotone map, noise
    for label, Ls, wants in cases:
        r = rank_scale(X, Ls, Ls.sum(1), "sum", lows.get(label))
        if label in lows:
            wants = dict(wants, **{LOW_FIDELITY: 0.99 if label == "quadratic bowl" else None})
        for name, floor in wants.items():
            t = np.median(r[name][0])
            good = abs(t) < 0.3 if floor is None else t >= floor
            ok = ok and good
            want = "|tau| < 0.3" if floor is None else f"tau >= {floor}"
            print(f"{label:15s} {name:28s} median tau {t:6.3f} (want {want}) {'ok' if good else 'FAILED'}")
    # Two sequences, exp of two bowls: a file combined by worst (max + rho sum, as most
    # calibrations) and one by the max alone (no rule of combined_objective).
    two = np.exp(0.05 * np.stack([bowl[:, 0], np.einsum("ni,ij,nj->n", X + c, H, X + c) + 0.1], 1))
    ok = points_file_case("worst", X, two, two.max(1) + RHO * two.sum(1), "worst") and ok
    ok = points_file_case("max", X, two, two.max(1), None) and ok
    return 0 if ok else 1


def points_file_case(label, X, Ls, combined, rule):
    """A points file whose L_combined is `combined` (not the sum of its L_ columns), read and
    reported as the bench's: the rule read must be `rule`, the combined L printed must be
    L_combined's (min and max), and the per-sequence model, where a rule is known, must rank it
    (tau >= 0.9; left out where none is)."""
    scale = 0.5
    with tempfile.TemporaryDirectory() as tmp:
        path = os.path.join(tmp, "points.csv")
        with open(path, "w") as f:
            f.write("scale,sample," + ",".join(f"d_p{i}" for i in range(X.shape[1])) +
                    "".join(f",L_s{k}" for k in range(Ls.shape[1])) + ",L_combined\n")
            for i in range(len(X)):
                f.write(f"{scale},{i}," + ",".join(f"{v:.17g}" for v in scale * X[i]) +
                        "".join(f",{v:.17g}" for v in Ls[i]) + f",{combined[i]:.17g}\n")
        text = io.StringIO()
        with contextlib.redirect_stdout(text):
            by_scale, read_rule = read_points(path)
            results = report(by_scale, read_rule)[scale]
    text = text.getvalue()
    want = f"combined L min {combined.min():.3f} median {np.median(combined):.3f} max {combined.max():.3f}"
    checks = [(f"the rule read, {read_rule}", read_rule == rule),
              (f"prints '{want}'", want in text)]
    if rule is None:
        checks.append((f"'{PER_SEQUENCE}' left out", PER_SEQUENCE not in results))
    else:
        t = np.median(results[PER_SEQUENCE][0]) if PER_SEQUENCE in results else float("nan")
        checks.append((f"'{PER_SEQUENCE}' median tau {t:.3f} (want >= 0.9)", t >= 0.9))
    for what, good in checks:
        print(f"points by {label:6s} {what} {'ok' if good else 'FAILED'}")
    return all(good for _, good in checks)


def main(argv):
    if argv[1:] == ["--self-test"]:
        return self_test()
    args = argv[1:]
    low = None
    if "--low-fidelity" in args:
        i = args.index("--low-fidelity")
        if i + 1 >= len(args):
            print("--low-fidelity needs a points file", file=sys.stderr)
            return 2
        low = read_points(args[i + 1])[0]
        del args[i:i + 2]
    if len(args) not in (1, 2):
        print(__doc__, file=sys.stderr)
        return 2
    results = report(*read_points(args[0]), low)
    if len(args) == 2:
        plot(results, args[1])
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
