"""The leaderboard's COCO-style figures: convergence (best cost so far) and the ECDF of targets solved, a panel
per participant pooling its instances; the ranking's critical-difference diagram.

Pictures take data: each panel is a `ConvergencePanel` or an `EcdfPanel` of arrays and labels, computed by the
leaderboard (`bench.leaderboard.curves`) from its board; nothing here reads a run log or a board."""

from __future__ import annotations

import os
from collections.abc import Iterable, Sequence
from dataclasses import dataclass

import numpy as np

_RGBA = tuple[float, float, float, float]


@dataclass(frozen=True)
class ConvergencePanel:
    """One participant's panel of the convergence figure.

    participant: its name (the panel's title); instances: how many of its problems the panel pools;
    curves: calibrator label -> the best-so-far cost curves of its runs, each (evaluations,) divided by its
    instance's hidden-truth cost (the population's without a truth), in the runs' order; labels without a
    run are absent; population: the population design's cost over the same scale, median over the
    instances; truths: whether every instance has a hidden truth (its line is drawn at 1)."""

    participant: str
    instances: int
    curves: dict[str, tuple[np.ndarray, ...]]
    population: float
    truths: bool


@dataclass(frozen=True)
class EcdfPanel:
    """One panel of the ECDF figure: a group of problems (all of them, or one participant's instances).

    name: the panel's title; targets: how many targets its problems have (0 when no calibrator ran on
    them); solved: calibrator label -> (sorted evaluations at which each solved (run, target) pair was
    first reached, (solved,); the number of (run, target) pairs); labels without a pair are absent."""

    name: str
    targets: int
    solved: dict[str, tuple[np.ndarray, int]]


def colors(labels: Iterable[str]) -> dict[str, _RGBA]:
    """A distinct colour per label: tab10's ten, then black, then tab20's ten light hues (cycled beyond 21)."""
    import matplotlib

    tab10, tab20 = matplotlib.colormaps["tab10"], matplotlib.colormaps["tab20"]
    palette = [tab10(i) for i in range(10)] + [(0.0, 0.0, 0.0, 1.0)] + [tab20(2 * i + 1) for i in range(10)]
    return {label: palette[i % len(palette)] for i, label in enumerate(labels)}


def _reference_line(ax, cost: float, text: str, color: str, style: str, *, right: bool) -> None:
    """A horizontal line at a reference design's cost, labelled at the right (above) or left (below) end."""
    ax.axhline(cost, color=color, ls=style, lw=1.0 if right else 1.2)
    x, ha, va = (0.99, "right", "bottom") if right else (0.01, "left", "top")
    ax.text(x, cost, text, color=color, fontsize=8, ha=ha, va=va, transform=ax.get_yaxis_transform())


def _panels(n: int, ncols: int, height: float, **kwargs):
    """A figure of `n` panels, `ncols` a row (4.6 wide, `height` tall each), the spare axes hidden: (fig, axes 2-D)."""
    import matplotlib.pyplot as plt

    nrows = -(-n // ncols)
    fig, axes = plt.subplots(
        nrows,
        ncols,
        figsize=(4.6 * ncols + 0.4, height * nrows + 0.5),
        squeeze=False,
        constrained_layout=True,
        **kwargs,
    )
    for ax in axes.flat[n:]:
        ax.set_visible(False)
    return fig, axes


def _save(fig, axes, path: str | os.PathLike, ylabel: str, legend_columns: int) -> None:
    """`ylabel` on each row's first panel, the first panel's legend below the panels; written to `path`, closed."""
    import matplotlib.pyplot as plt

    for row in axes:
        row[0].set_ylabel(ylabel)
    handles, names = axes[0, 0].get_legend_handles_labels()
    fig.legend(
        handles,
        names,
        loc="outside lower center",
        ncol=min(legend_columns, max(1, len(names))),
        fontsize=9,
        frameon=False,
    )
    fig.savefig(path, dpi=110)
    plt.close(fig)


def convergence_figure(
    path: str | os.PathLike, panels: Sequence[ConvergencePanel], colors: dict[str, _RGBA], budget: int
) -> None:
    """Best cost so far relative to the hidden truth's cost against evaluations (1 .. `budget`): median and
    IQR band over all runs (instances × seeds) per calibrator, a panel per participant (each run divided by
    its own instance's truth cost, so instances pool)."""
    n = len(panels)
    fig, axes = _panels(n, min(n, 3), 4.0)
    for ax, panel in zip(axes.flat, panels):
        lows, runs = [], set()
        for label, cs in panel.curves.items():
            length = max(len(c) for c in cs)
            stack = np.array([np.concatenate([c, np.full(length - len(c), c[-1])]) for c in cs])
            x = np.arange(1, length + 1)
            q25, med, q75 = np.quantile(stack, [0.25, 0.5, 0.75], axis=0)
            lows.append(float(q25.min()))
            ax.plot(x, med, color=colors[label], lw=1.8, label=label)
            runs.add(len(cs))
            ax.fill_between(x, q25, q75, color=colors[label], alpha=0.18, lw=0)
        pop = panel.population
        _reference_line(ax, pop, "population (median)", "0.35", "--", right=True)
        truths = panel.truths
        if truths:
            _reference_line(ax, 1.0, "hidden truth", "0.1", ":", right=False)
        ax.set_yscale("log")
        ax.set_ylim(min([1.0 if truths else np.inf] + lows) * 0.85, 1.6 * pop)  # failed runs (cost 1000) squash it
        _plain_log_ticks(ax.yaxis, subs=(1.0, 1.5, 2.0, 3.0, 4.0, 5.0, 7.0))
        k = panel.instances
        count = f"{max(runs)}" if len(runs) == 1 else f"≤ {max(runs, default=0)}"
        ax.set_title(f"{panel.participant}: {k} instance{'s' if k > 1 else ''}, {count} runs per calibrator")
        ax.set_xlabel("evaluations")
        ax.grid(True, which="both", alpha=0.25)
        ax.set_xlim(1, budget)
    _save(fig, axes, path, "calibration trial: best cost so far / hidden\ntruth's cost (median, IQR band over runs)", 4)


def _plain_log_ticks(axis, subs=(1.0, 2.0, 5.0)) -> None:
    """Log-axis ticks as plain numbers (1, 2, 5, 10, …) instead of 2 × 10^0."""
    from matplotlib.ticker import FuncFormatter, LogLocator, NullFormatter

    axis.set_major_locator(LogLocator(base=10, subs=subs))
    axis.set_major_formatter(FuncFormatter(lambda v, _: f"{v:g}"))
    axis.set_minor_formatter(NullFormatter())


def ecdf_figure(path: str | os.PathLike, panels: Sequence[EcdfPanel], colors: dict[str, _RGBA], budget: int) -> None:
    """COCO-style ECDF of (run, target) pairs solved against evaluations (1 .. `budget`, log): a panel of all
    problems, then one per participant pooling its instances (`EcdfPanel`)."""
    n = len(panels)
    fig, axes = _panels(n, n if n <= 3 else 2 if n == 4 else 3, 3.9, sharey=True)
    top = budget
    grid = np.unique(np.round(np.geomspace(1, top, 200)).astype(int))
    for ax, panel in zip(axes.flat, panels):
        for label, (hits, pairs) in panel.solved.items():
            frac = np.searchsorted(hits, grid, side="right") / pairs
            ax.step(grid, frac, where="post", color=colors[label], lw=1.8, label=label)
        ax.set_xscale("log")
        ax.set_xlim(1, top)
        _plain_log_ticks(ax.xaxis)
        ax.set_ylim(0, 1.02)
        ax.set_xlabel("evaluations")
        ax.set_title(f"{panel.name} ({panel.targets} targets)")
        ax.grid(True, which="both", alpha=0.25)
    for row in axes:
        row[0].tick_params(labelleft=True)
    _save(fig, axes, path, "fraction of (run, target) pairs solved", 5)


def ranking_figure(path: str | os.PathLike, result, title: str) -> None:
    """The critical-difference diagram of a ranking (`autorank.plot_stats` of its `RankResult`, drawn even when
    Friedman's test does not reject: the title says so): mean ranks on the axis, bars joining calibrators the
    Nemenyi test cannot separate."""
    import warnings

    import autorank
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(7.5, 0.6 + 0.32 * len(result.rankdf)))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        autorank.plot_stats(result, allow_insignificant=True, ax=ax)
    ax.set_title(title, fontsize=9)
    fig.savefig(path, dpi=110, bbox_inches="tight")
    plt.close(fig)
