"""The figures of a design map (``biped.studies.design_map``): per speed, the optimal
criterion over the knee radii (r1, r2) with the joint optimum, the Table 1 radii and the
revolute knee's value as a contour (``map_figure``); with several speeds, the optimal radii
and the gains against the revolute knee over the speeds; all written, with the map's
``summary.csv``, by ``draw``.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
from matplotlib.figure import Figure

from biped.model.criteria import CRITERION_UNITS
from biped.optimization.design import RADII
from biped.pages.style import DESIGN_MAP_SIZE, DESIGN_SPEEDS_SIZE, FONT_HEADING, FONT_NOTE, save
from biped.runtime.files import atomic_write_text
from biped.studies.design_map import (
    MapPoint,
    MapSettings,
    SpeedSummary,
    load,
    speed_summaries,
    summary_csv,
)


def measured_points(settings: MapSettings, summary: SpeedSummary, results: dict) -> list:
    """The certified optima of one speed's map as (r1, r2, value) [m, m, the criterion's
    unit]: the grid's, and the Table 1 radii's and the joint optimum's where they lie within
    the grid's span (a point the grid holds already is not repeated)."""
    points = {}
    for a in settings.r1:
        for b in settings.r2:
            content = results.get(MapPoint("grid", summary.speed, (a, b)))
            if content is not None and content["certified"]:
                points[round(a, 4), round(b, 4)] = content["value"]
    table1 = settings.problem(summary.speed).reference_radii
    others = [(table1, summary.table1), (summary.radii, summary.design)]
    for radii, value in others:
        if radii is None or value is None:
            continue
        grids = (settings.r1, settings.r2)
        if all(min(g) <= r <= max(g) for r, g in zip(radii, grids, strict=True)):
            points.setdefault((round(radii[0], 4), round(radii[1], 4)), value)
    return [(a, b, value) for (a, b), value in points.items()]


def _map_surface(fig, ax, settings: MapSettings, summary: SpeedSummary, points: list) -> str:
    """The criterion over (r1, r2), linear between the measured points (a triangulation of
    them: at each point its own value, so no point lies on the wrong side of the revolute
    knee's contour), and that contour; "" if drawn, else why there is no map."""
    from matplotlib.tri import Triangulation

    unit = CRITERION_UNITS[settings.criterion]
    counts = (len(settings.r1), len(settings.r2))
    if min(counts) < 2:
        return (
            f"no map: the grid has {counts[0]} value{'s' * (counts[0] > 1)} of r1 and "
            f"{counts[1]} of r2\n(a map needs 2 or more of each): each point gives its value"
        )
    try:
        x, y, values = (np.array(column, float) for column in zip(*points, strict=True))
        mesh = Triangulation(100 * x, 100 * y)
    except (ValueError, RuntimeError):  # fewer than 3 points, or all on a line
        return (
            f"no map: {len(points)} certified points of the grid, not spanning an area:\n"
            "each point gives its value"
        )
    filled = ax.tricontourf(mesh, values, levels=16, cmap="viridis")
    bar = fig.colorbar(filled, ax=ax, label=f"optimal {settings.criterion} criterion [{unit}]")
    if summary.revolute is not None and values.min() <= summary.revolute <= values.max():
        # where the rolling knee costs what the revolute knee does (on the axes r1 = 0 and
        # r2 = 0 it is a hinge: there exactly)
        ax.tricontour(
            mesh, values, levels=[summary.revolute], colors="k", linestyles="--", linewidths=1.2
        )
        bar.ax.axhline(summary.revolute, color="k", ls="--", lw=1.5)
        ax.plot([], [], "k--", label="revolute knee's value (linear between the points)")
    return ""


def _point_values(ax, settings: MapSettings, summary: SpeedSummary, points: list) -> None:
    """Each certified point's value beside it, and its change against the revolute knee's
    (a map without its surface)."""
    unit = CRITERION_UNITS[settings.criterion]
    table1 = settings.problem(summary.speed).reference_radii
    shown = {(round(a, 4), round(b, 4)): value for a, b, value in points}
    for radii, value in ((table1, summary.table1), (summary.radii, summary.design)):
        if radii is not None and value is not None:
            shown.setdefault((round(radii[0], 4), round(radii[1], 4)), value)
    middle = 0.5 * max(max(settings.r1), settings.upper[0])  # labels toward the centre
    for (a, b), value in shown.items():
        change = summary.gain(value)
        versus = "" if change is None else f" ({change:+.2f} % vs revolute)"
        side = -1 if a > middle else 1
        ax.annotate(
            f"{value:.4g} {unit}{versus}", (100 * a, 100 * b), xytext=(7 * side, -4),
            textcoords="offset points", fontsize=FONT_NOTE, va="top",
            ha="right" if side < 0 else "left",
        )  # fmt: skip


def map_figure(settings: MapSettings, summary: SpeedSummary, results: dict):
    """The map of one speed (a matplotlib ``Figure``): the optimal criterion over (r1, r2),
    linear between the measured points, the revolute knee's value as a dashed contour, the
    grid points, the Table 1 radii and the joint optimum; the legend below the plot, off the
    grid. Without a map (a grid of one radius), a note says why and each point its value."""
    unit = CRITERION_UNITS[settings.criterion]
    r1, r2 = np.array(settings.r1), np.array(settings.r2)
    table1 = settings.problem(settings.speeds[0]).reference_radii
    points = measured_points(settings, summary, results)
    fig = Figure(figsize=DESIGN_MAP_SIZE, layout="constrained")
    ax = fig.subplots()
    why = _map_surface(fig, ax, settings, summary, points)
    if why:
        _point_values(ax, settings, summary, points)
    ax.scatter(100 * np.repeat(r1, len(r2)), 100 * np.tile(r2, len(r1)), s=4, c="k")
    ax.plot(100 * table1[0], 100 * table1[1], "s", color="tab:orange", label="Table 1 radii")
    if summary.radii is not None:
        ax.plot(
            100 * summary.radii[0],
            100 * summary.radii[1],
            "*",
            color="tab:red",
            markersize=14,
            label="joint optimum",
        )
    revolute = "n/a" if summary.revolute is None else f"{summary.revolute:.4g} {unit}"
    ax.set_title(
        f"{settings.criterion} at {summary.speed:.3f} m/s (revolute knee {revolute})"
        + (f"\n{why}" if why else ""),
        fontsize=FONT_HEADING,
    )
    for axis, grid, bound in (
        (ax.set_xlim, r1, settings.upper[0]),
        (ax.set_ylim, r2, settings.upper[1]),
    ):
        top = 100 * max(grid.max(), bound)
        axis(-0.03 * top, 1.04 * top)
    ax.set_xlabel("r1, shank circle [cm]")
    ax.set_ylabel("r2, thigh circle [cm]")
    # below the plot, not over it: the grid's corners (the Table 1 radii) stay in sight
    fig.legend(loc="outside lower center", ncol=3, fontsize=FONT_NOTE)
    return fig


def speeds_figure(settings: MapSettings, summaries: list[SpeedSummary]) -> Figure:
    """The optimal radii (left, their upper bounds dotted) and the gains of the optimal and
    the Table 1 radii against the revolute knee (right), over the map's speeds."""
    speeds = [s.speed for s in summaries]
    fig = Figure(figsize=DESIGN_SPEEDS_SIZE)
    left, right = fig.subplots(1, 2)
    for index, name in enumerate(RADII):
        radii = [np.nan if s.radii is None else 100 * s.radii[index] for s in summaries]
        left.plot(speeds, radii, "o-", label=f"optimal {name}")
        left.axhline(100 * settings.upper[index], color=f"C{index}", ls=":", lw=1)
    left.set_xlabel("speed [m/s]")
    left.set_ylabel("radius [cm] (dotted: upper bound)")
    left.legend()
    for label, pick in (
        ("optimal radii", lambda s: s.design),
        ("Table 1 radii", lambda s: s.table1),
    ):
        gains = [s.gain(pick(s)) for s in summaries]
        right.plot(speeds, [np.nan if g is None else g for g in gains], "o-", label=label)
    right.axhline(0.0, color="k", lw=0.8)
    right.set_xlabel("speed [m/s]")
    right.set_ylabel(f"{settings.criterion} vs revolute knee [%]")
    right.legend()
    fig.tight_layout()
    return fig


def draw(folder, out=None) -> list[Path]:
    """The map's figures and summary in ``out`` (default: the map's folder)."""
    settings, results = load(folder)
    out = Path(folder if out is None else out)
    out.mkdir(parents=True, exist_ok=True)
    summaries = speed_summaries(settings, results)
    written = [
        save(map_figure(settings, summary, results), out / f"map-{summary.speed:.3f}.png")
        for summary in summaries
    ]
    if len(summaries) > 1:
        written.append(save(speeds_figure(settings, summaries), out / "speeds.png"))
    written.append(atomic_write_text(out / "summary.csv", summary_csv(settings, results)))
    return written
