#!/usr/bin/python3
"""The numbers and figures of docs/answers.md ("which parameterization for what") from the CSV
files of `halfback study` and of scripts/factor_study.py.

    /usr/bin/python3 scripts/answers.py --out DIR [--page PAGE.md] [--factored FACTORED.csv] STUDY_DIR...

Each table (azimuthal, separability, gonio, image, sampling, fit) is read from the first STUDY_DIR
that has it, and every gonio-format file named gonio*.csv, sequential.csv or nielsen.csv in the
STUDY_DIRs is added to the acquisition strategies (a row given twice with different errors is an
error). Writes DIR/answers.md (one table per use, the sources of each), DIR/answers.json (the
same numbers) and one figure per use, DIR/answers-USE.png. With --page, replaces every block
between `<!-- answers:USE -->` and `<!-- /answers:USE -->` of PAGE.md by the table of USE and
the block `<!-- answers:sources -->` by the list of sources, in place (atomically).

The kinds of material are those of docs/study.md ("Importance sampling"): a BRDF's half-vector
table (halfdiff's chart, tabulated sampler, the largest table of the run) against the cosine on
the albedo: broad below 30, intermediate 30-300, peaked above 300. A BRDF without a sampling row
is "unsampled". Every number is a median over the BRDFs of a kind measured in every
parameterization compared; "margin" is the runner-up's median over the winner's (how many times
worse the second best is), or for the sampling efficiency (higher is better) the winner's over
the runner-up's.
"""

import argparse
import csv
import json
import math
import os
import statistics
import sys
import tempfile
from collections import defaultdict
from pathlib import Path

GROUPS = [("broad", 0, 30), ("intermediate", 30, 300), ("peaked", 300, math.inf)]
KINDS = [g[0] for g in GROUPS] + ["all"]
ROUND_OFF_LOSS = 1e-20  # the study's kRoundOffLoss: a fit's loss below it is exact
COLOURS = {  # one colour each, distinct for the eight built-ins and the strategies
    "halfdiff": "#1f77b4", "ortho": "#ff7f0e", "hybrid": "#2ca02c", "rectified-hybrid": "#d62728",
    "stereo-halfdiff": "#9467bd", "stereographic": "#8c564b", "halfway-disk": "#e377c2",
    "spherical": "#7f7f7f", "cosine": "#17becf", "dupuy-jakob": "#bcbd22", "nielsen": "#000000",
    "lambert+ggx": "#000000"}


def read_csv(path):
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


class Sources:
    """Which file each table came from."""

    def __init__(self, dirs):
        self.dirs = [Path(d) for d in dirs]
        self.used = {}

    def table(self, name):
        for d in self.dirs:
            p = d / f"{name}.csv"
            if p.exists():
                self.used[name] = str(p)
                return read_csv(p)
        return []

    def gonio_rows(self):
        rows, seen = [], {}
        files = []
        for d in self.dirs:
            for p in sorted(d.glob("gonio*.csv")) + sorted(d.glob("sequential.csv")) + sorted(
                    d.glob("nielsen.csv")):
                files.append(p)
        for p in files:
            for r in read_csv(p):
                if r["dims"] != "3":
                    continue
                key = (r["brdf"], r["parameterization"], r["design"], r["spacing"], r["budget"])
                if key in seen:
                    if seen[key] != r["error"]:
                        sys.exit(f"answers.py: {p}: {key} given twice with different errors")
                    continue
                seen[key] = r["error"]
                rows.append(r)
        if files:
            self.used["gonio (acquisition)"] = ", ".join(str(p) for p in files)
        return rows


def median(v):
    return statistics.median(v) if v else math.nan


def groups_of(sampling):
    """BRDF -> kind, from the half-vector table's albedo efficiency at the largest table."""
    rows = [r for r in sampling if r["parameterization"] == "halfdiff" and r["sampler"] == "tabulated"]
    if not rows:
        return {}, None
    kib = max(int(r["table_kib"]) for r in rows)
    group = {}
    for r in rows:
        if int(r["table_kib"]) != kib:
            continue
        e = float(r["efficiency_vs_cosine"])
        for name, lo, hi in GROUPS:
            if lo <= e < hi:
                group[r["brdf"]] = name
    return group, kib


def compare(values, params, lower_is_better=True):
    """values: brdf -> {param: value}. Per kind: BRDFs measured in all params, each param's
    median, the winner, runner-up, margin and the winner's wins."""
    out = {}
    for kind in KINDS:
        brdfs = [b for b, v in values.items() if all(p in v and math.isfinite(v[p]) for p in params)
                 and (kind == "all" or GROUP.get(b, "unsampled") == kind)]
        if not brdfs:
            continue
        med = {p: median([values[b][p] for b in brdfs]) for p in params}
        order = sorted(params, key=lambda p: med[p] if lower_is_better else -med[p])
        best, second = order[0], order[1] if len(order) > 1 else None
        wins = 0
        for b in brdfs:
            top = min(values[b][p] for p in params) if lower_is_better else max(values[b][p] for p in params)
            wins += values[b][best] == top
        margin = None
        if second is not None and med[best] > 0 and med[second] > 0:
            margin = med[second] / med[best] if lower_is_better else med[best] / med[second]
        out[kind] = {"brdfs": len(brdfs), "medians": med, "winner": best, "runner_up": second,
                     "margin": margin, "winner_lowest_on": wins}
    return out


def fmt(x):
    if x is None or (isinstance(x, float) and not math.isfinite(x)):
        return "–"
    return f"{x:.3g}"


def table_md(result, params, what):
    head = "| kind | BRDFs | " + " | ".join(params) + " | winner | margin | winner best on |\n"
    head += "|---" * (len(params) + 5) + "|\n"
    rows = ""
    for kind in KINDS:
        if kind not in result:
            continue
        r = result[kind]
        cells = []
        for p in params:
            c = fmt(r["medians"][p])
            cells.append(f"**{c}**" if p == r["winner"] else c)
        margin = f"×{r['margin']:.2f}" if r["margin"] else "–"
        rows += (f"| {kind} | {r['brdfs']} | " + " | ".join(cells) +
                 f" | {r['winner']} | {margin} | {r['winner_lowest_on']} of {r['brdfs']} |\n")
    return f"{what}\n\n{head}{rows}"


def params_in(rows):
    seen = []
    for r in rows:
        if r["parameterization"] not in seen:
            seen.append(r["parameterization"])
    return seen


# ---------------------------------------------------------------------------------------------
# The uses
# ---------------------------------------------------------------------------------------------

def compactness(src):
    az, sep = src.table("azimuthal"), src.table("separability")
    if not sep:
        return None
    params = params_in(sep)
    sep_v = defaultdict(dict)
    for r in sep:
        if r["dims"] == "2" and r["rank"] == "1":
            sep_v[r["brdf"]][r["parameterization"]] = float(r["error"])
    az_v = defaultdict(dict)
    for r in az:
        if r["dims"] == "3":
            az_v[r["brdf"]][r["parameterization"]] = float(r["error"])
    return {"params": params,
            "tables": [("separability: the relative error of the best rank-1 term of the 2D "
                        "projection (median; lower is better)", compare(sep_v, params), sep_v),
                       ("azimuthal dependence: the relative error of dropping the relative "
                        "azimuth (median; lower is better)", compare(az_v, params), az_v)]}


def interpolation(src, rows):
    params = [p for p in params_in(rows) if not p.startswith("dupuy-jakob")]
    budgets = sorted({int(r["budget"]) for r in rows if r["design"] == "regular" and r["spacing"] == "own"})
    if not budgets:
        return None
    ref = 10000 if 10000 in budgets else budgets[len(budgets) // 2]
    reg = defaultdict(dict)
    for r in rows:
        if r["design"] == "regular" and r["spacing"] == "own" and int(r["budget"]) == ref:
            reg[r["brdf"]][r["parameterization"]] = float(r["error"])
    img = defaultdict(lambda: defaultdict(list))
    for r in src.table("image"):
        if r["design"] == "regular":
            img[r["brdf"]][r["parameterization"]].append(float(r["relative_rmse"]))
    img_v = {b: {p: statistics.mean(v) for p, v in d.items()} for b, d in img.items()}
    tables = [(f"the gonio-reflectometer's relative error at N = {ref}, regular grid uniform in "
               "each parameterization's own coordinates (median; lower is better)",
               compare(reg, params), reg)]
    if img_v:
        tables.append(("renderings of those reconstructions: image-space relative RMSE, mean over "
                       "the environments (median; lower is better)", compare(img_v, params), img_v))
    return {"params": params, "ref": ref, "tables": tables}


def strategy_name(r):
    d, s, p = r["design"], r["spacing"], r["parameterization"]
    if d in ("nielsen", "dupuy-jakob"):
        return d
    if p.startswith("dupuy-jakob"):
        return None
    if d == "sequential":
        return f"{p} sequential"
    return f"{p} {d}" + ("" if s == "own" else f" ({s})")


def acquisition(rows):
    by = defaultdict(lambda: defaultdict(dict))  # budget -> brdf -> strategy -> error
    for r in rows:
        name = strategy_name(r)
        if name is None:
            continue
        by[int(r["budget"])][r["brdf"]][name] = float(r["error"])
    if not by:
        return None
    # The strategies compared: for each parameterization its best design at 10^4 over all BRDFs
    # (as an instrument is built once), and the sequential, Dupuy & Jakob and Nielsen designs.
    ref = 10000 if 10000 in by else sorted(by)[len(by) // 2]
    names = sorted({n for d in by[ref].values() for n in d})
    med = {n: median([d[n] for d in by[ref].values() if n in d]) for n in names}
    best_of = {}
    for n in names:
        if n in ("nielsen", "dupuy-jakob") or n.endswith("sequential"):
            continue
        p = n.split(" ")[0]
        if p not in best_of or med[n] < med[best_of[p]]:
            best_of[p] = n
    chosen = sorted(best_of.values(), key=lambda n: med[n])[:3]
    if "halfdiff regular" in names and "halfdiff regular" not in chosen:
        chosen.insert(0, "halfdiff regular")  # the plain grid, the reference of every strategy
    for extra in sorted(names):
        if extra.endswith("sequential") and med[extra] == min(
                med[n] for n in names if n.endswith("sequential")):
            chosen.append(extra)
    chosen += [n for n in ("dupuy-jakob",) if n in names]
    tables = []
    curves = {}
    # The budgets at which every strategy chosen is measured (all of them when there is none).
    full = [b for b in sorted(by) if all(any(n in d for d in by[b].values()) for n in chosen)]
    for budget in full or sorted(by):
        have = [n for n in chosen if any(n in d for d in by[budget].values())]
        if len(have) < 2:
            continue
        res = compare(by[budget], have)
        tables.append((f"N = {budget}: the relative error of each strategy's reconstruction "
                       "(median over the BRDFs measured by all of them; lower is better)",
                       res, by[budget]))
        for kind, r in res.items():
            for n in have:
                curves.setdefault(kind, {}).setdefault(n, []).append((budget, r["medians"][n]))
    nielsen = {}
    for budget in sorted(by):
        v = [d["nielsen"] for d in by[budget].values() if "nielsen" in d]
        if v:
            nielsen[budget] = median(v)
    return {"chosen": chosen, "ref": ref, "tables": tables, "curves": curves, "nielsen": nielsen}


def fitting(src):
    rows = src.table("fit")
    if not rows:
        return None
    params = params_in(rows)
    budgets = sorted({int(r["budget"]) for r in rows})
    tables = []
    for weights, design in (("solid-angle", "stratified"), ("uniform", "regular")):
        for budget in budgets[-1:]:
            v = defaultdict(dict)
            for r in rows:
                if (r["weights"], r["design"], int(r["budget"])) != (weights, design, budget):
                    continue
                whole, layout = float(r["whole_loss"]), float(r["layout_loss"])
                if whole < ROUND_OFF_LOSS:
                    continue  # fitted exactly: a ratio of round-off
                v[r["brdf"]][r["parameterization"]] = layout / whole - 1
            tables.append((f"{weights} weights, {design} design, {budget} measurements: the excess "
                           "of the fit from the measurements over the fit of the whole BRDF, on "
                           "the whole BRDF (median; 0: as good; lower is better)",
                           compare(v, params), v))
    return {"params": params, "tables": tables}


def sampling(src):
    rows = [r for r in src.table("sampling") if r["sampler"] == "tabulated"]
    if not rows:
        return None
    params = params_in(rows)
    # Parameterizations that share a chart share the sampler: one column per chart, named by
    # its parameterizations.
    chart_of = {}
    for r in rows:
        chart_of.setdefault(r["chart"], [])
        if r["parameterization"] not in chart_of[r["chart"]]:
            chart_of[r["chart"]].append(r["parameterization"])
    label = {c: "/".join(ps) for c, ps in chart_of.items()}
    charts = sorted(chart_of, key=lambda c: params.index(chart_of[c][0]))
    tables = []
    values = {}
    for kib in sorted({int(r["table_kib"]) for r in rows}):
        for column, what in (("efficiency_vs_cosine", "the albedo estimate's efficiency against "
                              "cosine sampling"),
                             ("pixel_efficiency_vs_cosine_mis", "the rendering's efficiency "
                              "against cosine sampling, with MIS")):
            v = defaultdict(dict)
            for r in rows:
                if int(r["table_kib"]) == kib:
                    v[r["brdf"]][label[r["chart"]]] = float(r[column])
            cols = [label[c] for c in charts]
            tables.append((f"tables of {kib} KiB: {what} (median; higher is better, above 1 the "
                           "table beats the cosine)", compare(v, cols, lower_is_better=False), v))
            values[(kib, column)] = (cols, v)
    return {"tables": tables, "values": values}


def study_label(spec):
    """The study's label of a BRDF given by path in factor_study.py's rows (a neural BRDF's file
    is "nbrdf:NAME" in the study), so that it has its kind of material."""
    if spec in GROUP:
        return spec
    p = Path(spec)
    return f"nbrdf:{p.stem}" if p.suffix == ".h5" else spec


def factored(path):
    if not path or not Path(path).exists():
        return None
    rows = read_csv(path)
    for r in rows:
        r["brdf"] = study_label(r["brdf"])
    params = params_in(rows)
    tables = []
    for rank in sorted({int(r["rank"]) for r in rows}):
        v = defaultdict(dict)
        for r in rows:
            if int(r["rank"]) == rank:
                v[r["brdf"]][r["parameterization"]] = float(r["loss"])
                v[r["brdf"]]["lambert+ggx"] = float(r["model_loss"])
        numbers = {r["parameterization"]: r["numbers"] for r in rows if int(r["rank"]) == rank}
        tables.append((f"rank {rank} ({', '.join(f'{p} {n}' for p, n in numbers.items())} numbers; "
                       "lambert+ggx 7): the model's loss on the whole BRDF (median; lower is "
                       "better)", compare(v, params + ["lambert+ggx"]), v))
    return {"params": params, "tables": tables}


# ---------------------------------------------------------------------------------------------
# Figures (matplotlib): per parameterization, the distribution over the BRDFs, one box per kind
# ---------------------------------------------------------------------------------------------

def box_figure(path, title, ylabel, values, columns, log=True, reference=None):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    kinds = [k for k, _, _ in GROUPS if any(GROUP.get(b) == k for b in values)] or ["all"]
    fig, ax = plt.subplots(figsize=(max(6, 1.1 * len(columns) * max(1, len(kinds)) / 2 + 2), 4.2))
    width = 0.8 / len(kinds)
    shades = {"broad": "#a6cee3", "intermediate": "#fdbf6f", "peaked": "#fb9a99", "all": "#cccccc"}
    for k, kind in enumerate(kinds):
        data, pos = [], []
        for i, c in enumerate(columns):
            v = [d[c] for b, d in values.items() if c in d and math.isfinite(d[c]) and d[c] > 0
                 and (kind == "all" or GROUP.get(b) == kind)]
            if v:
                data.append(v)
                pos.append(i + (k - (len(kinds) - 1) / 2) * width)
        if not data:
            continue
        # Whiskers at the 5th and 95th percentiles, no points beyond: matplotlib's default (1.5
        # interquartile ranges, in linear units) reaches down to an exact reconstruction's 1e-16
        # on a log axis and squashes every box into its top tenth.
        bp = ax.boxplot(data, positions=pos, widths=width * 0.9, patch_artist=True, whis=(5, 95),
                        showfliers=False, medianprops={"color": "black"})
        for patch in bp["boxes"]:
            patch.set_facecolor(shades[kind])
        ax.plot([], [], "s", color=shades[kind], label=f"{kind} ({sum(1 for b in values if kind == 'all' or GROUP.get(b) == kind)})")
    if reference is not None:
        ax.axhline(reference[0], color="#555555", lw=1, ls="--")
        ax.text(len(columns) - 0.5, reference[0], " " + reference[1], va="bottom", ha="right",
                fontsize=8, color="#555555")
    ax.set_xticks(range(len(columns)))
    ax.set_xticklabels(columns, rotation=20, ha="right")
    if log:
        ax.set_yscale("log")
    ax.set_ylabel(ylabel)
    ax.set_title(title, fontsize=10)
    ax.grid(axis="y", alpha=0.3)
    ax.legend(fontsize=8, title="kind of material (BRDFs);\nwhiskers: 5th-95th percentile", title_fontsize=8,
              loc="upper left", bbox_to_anchor=(1.01, 1))  # beside the plot: over no box
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def strategies_figure(path, acq):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    kinds = [k for k in KINDS if k in acq["curves"] and k != "all"] or ["all"]
    fig, axes = plt.subplots(1, len(kinds), figsize=(4 * len(kinds), 3.8), sharey=True, squeeze=False)
    for ax, kind in zip(axes[0], kinds):
        for n, pts in acq["curves"][kind].items():
            xs, ys = zip(*pts)
            p = n.split(" ")[0]
            style = "s--" if "sequential" in n else "^:" if n == "halfdiff regular" else "o-"
            ax.plot(xs, ys, style, label=n, color=COLOURS.get(p, "#333333"),
                    alpha=0.6 if "sequential" in n or n == "halfdiff regular" else 0.9)
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_title(kind, fontsize=10)
        ax.set_xlabel("measurements (budget)")
        ax.grid(alpha=0.3)
    axes[0][0].set_ylabel("median relative error")
    axes[0][-1].legend(fontsize=7)
    fig.suptitle("Acquisition strategies: median error against the budget, per kind of material",
                 fontsize=10)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


# ---------------------------------------------------------------------------------------------

def write_atomically(path, text):
    path = Path(path)
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=path.name + ".")
    with os.fdopen(fd, "w") as f:
        f.write(text)
    os.chmod(tmp, path.stat().st_mode & 0o7777 if path.exists() else 0o644)
    os.replace(tmp, path)


def replace_blocks(page, blocks):
    text = Path(page).read_text()
    for name, body in blocks.items():
        start, end = f"<!-- answers:{name} -->", f"<!-- /answers:{name} -->"
        a, b = text.find(start), text.find(end)
        if a < 0 or b < a:
            sys.exit(f"answers.py: {page}: no block {start} ... {end}")
        text = text[:a + len(start)] + "\n" + body.rstrip() + "\n" + text[b:]
    write_atomically(page, text)


GROUP = {}


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--out", required=True)
    ap.add_argument("--page")
    ap.add_argument("--factored")
    ap.add_argument("dirs", nargs="+")
    a = ap.parse_args()
    out = Path(a.out)
    out.mkdir(parents=True, exist_ok=True)
    src = Sources(a.dirs)
    samp = src.table("sampling")
    group, kib = groups_of(samp)
    GROUP.update(group)
    gonio = src.gonio_rows()
    uses = {
        "compactness": compactness(src),
        "interpolation": interpolation(src, gonio),
        "acquisition": acquisition(gonio),
        "fitting": fitting(src),
        "sampling": sampling(src),
        "factored": factored(a.factored),
    }
    blocks, numbers = {}, {}
    for name, u in uses.items():
        if not u:
            blocks[name] = "(not measured in this run)"
            continue
        md = ""
        for what, res, _ in u["tables"]:
            md += table_md(res, list(next(iter(res.values()))["medians"]) if res else [], what) + "\n"
            numbers.setdefault(name, []).append({"what": what, "by_kind": res})
        blocks[name] = md
    if "acquisition" in numbers and uses["acquisition"]["nielsen"]:
        blocks["acquisition"] += ("Nielsen et al.'s minimal sampling (halfdiff, median over its BRDFs): " +
                                  ", ".join(f"{n} measurements {e:.3g}" for n, e in
                                            uses["acquisition"]["nielsen"].items()) + ".\n")
    # Figures
    figures = {}
    if uses["compactness"]:
        _, _, v = uses["compactness"]["tables"][0]
        box_figure(out / "answers-compactness.png", "Compactness: one separable term (rank 1, 2D projection)",
                   "relative error of the rank-1 term", v, uses["compactness"]["params"])
        figures["compactness"] = "answers-compactness.png"
    if uses["interpolation"]:
        _, _, v = uses["interpolation"]["tables"][0]
        box_figure(out / "answers-interpolation.png",
                   f"Interpolation: gonio-reflectometer, N = {uses['interpolation']['ref']}, regular grid",
                   "relative error of the reconstruction", v, uses["interpolation"]["params"])
        figures["interpolation"] = "answers-interpolation.png"
    if uses["acquisition"] and uses["acquisition"]["curves"]:
        strategies_figure(out / "answers-acquisition.png", uses["acquisition"])
        figures["acquisition"] = "answers-acquisition.png"
    if uses["fitting"]:
        _, _, v = uses["fitting"]["tables"][0]
        box_figure(out / "answers-fitting.png",
                   "Fitting lambert+ggx from measurements (solid-angle weights, stratified)",
                   "excess over the whole BRDF's fit", v, uses["fitting"]["params"])
        figures["fitting"] = "answers-fitting.png"
    if uses["sampling"]:
        kibs = sorted({k for k, _ in uses["sampling"]["values"]})
        cols, v = uses["sampling"]["values"][(kibs[-1], "efficiency_vs_cosine")]
        box_figure(out / "answers-sampling.png",
                   f"Importance sampling: tables of {kibs[-1]} KiB, albedo efficiency against the cosine",
                   "efficiency against cosine sampling (higher is better)", v, cols,
                   reference=(1, "cosine sampling"))
        figures["sampling"] = "answers-sampling.png"
    if uses["factored"]:
        t = [t for t in uses["factored"]["tables"] if t[0].startswith("rank 2")] or uses["factored"]["tables"]
        _, _, v = t[0]
        box_figure(out / "answers-factored.png", "Factored models, " + t[0][0].split(":")[0].split(" (")[0] +
                   ", against the lambert+ggx fit", "loss on the whole BRDF",
                   v, uses["factored"]["params"] + ["lambert+ggx"])
        figures["factored"] = "answers-factored.png"
    sources = "".join(f"- {k}: {v}\n" for k, v in src.used.items())
    if a.factored:
        sources += f"- factored models: {a.factored}\n"
    sources += (f"- kinds of material: halfdiff's tabulated sampler at {kib} KiB against the cosine "
                "(broad < 30, intermediate 30-300, peaked > 300)\n" if kib else
                "- kinds of material: none (no sampling table): every BRDF is in \"all\"\n")
    blocks["sources"] = sources
    doc = "# Answers: the numbers\n\nSources:\n\n" + sources + "\n"
    for name in uses:
        doc += f"## {name}\n\n" + blocks[name] + "\n"
        if name in figures:
            doc += f"![{name}]({figures[name]})\n\n"
    write_atomically(out / "answers.md", doc)
    write_atomically(out / "answers.json", json.dumps(numbers, indent=1, default=str))
    if a.page:
        replace_blocks(a.page, blocks)
    print(f"answers.py: {out / 'answers.md'}, {len(figures)} figures" + (f", {a.page} updated" if a.page else ""))


if __name__ == "__main__":
    main()
