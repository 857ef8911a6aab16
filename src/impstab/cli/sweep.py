"""Design-study commands: sweep (run or resume a study) and map (draw its stability map)."""

from __future__ import annotations

import sys
import time
from pathlib import Path

import click

from ..errors import ModelError
from ._common import check_number, console, draw_and_save, fmt, table

__all__ = ["commands"]

_EXPORTS = (".nc", ".csv")


class Interrupted(click.ClickException):
    """The study was interrupted (Ctrl-C); what was finished is kept (exit code 130)."""

    exit_code = 130


def _fmt(v, unit: str = "") -> str:
    if isinstance(v, (bool, str)) or v is None:
        return "n/a" if v is None else str(v)
    return fmt(v, unit)


@click.command("sweep")
@click.argument("study_file", type=click.Path(dir_okay=False))
@click.option("-o", "--output", "store", type=click.Path(), default=None,
              help="zarr store (a folder); default STUDY.zarr in the current folder. Rerun to resume.")
@click.option("--workers", type=int, default=None, help="start a local Dask cluster with N worker processes")
@click.option("--scheduler", default=None, help="address of an existing Dask scheduler (tcp://host:8786)")
@click.option("--export", "exports", multiple=True, type=click.Path(dir_okay=False),
              help="also write the results to FILE.nc (netCDF) or FILE.csv; may be repeated")
@click.option("--progress/--no-progress", default=None, help="progress bar (default: when the terminal shows one)")
def sweep_cmd(study_file: str, store: str | None, workers: int | None, scheduler: str | None,
              exports: tuple[str, ...], progress: bool | None) -> None:
    """Run the design study STUDY_FILE (or resume it) into a zarr store."""
    from ..studies import load_study, run_study

    if workers is not None and scheduler is not None:
        raise ModelError("--workers", workers, "give either --workers or --scheduler, not both")
    if workers is not None and workers < 1:
        raise ModelError("--workers", workers, "must be >= 1")
    for path in exports:
        if Path(path).suffix.lower() not in _EXPORTS:
            raise ModelError("--export", path, "must end in .nc (netCDF) or .csv")
    study = load_study(study_file)
    out = Path(store) if store else Path(Path(study_file).stem + ".zarr")
    if progress is None:
        progress = sys.stderr.isatty()
    t0 = time.perf_counter()
    try:
        res = run_study(study, out, workers=workers, scheduler=scheduler, progress=progress)
    except KeyboardInterrupt:
        raise Interrupted(f"interrupted; the chunks finished so far are kept in {out}: "
                          "run the same command again to resume") from None
    elapsed = time.perf_counter() - t0
    written = [str(res.export(p)) for p in exports]
    _summary(res, study, out, elapsed, written)


def _summary(res, study, out: Path, elapsed: float, written: list[str]) -> None:
    from ..model.reference import label, unit

    counts = res.counts()
    t = table(f"design study {study.name}: {study.size} designs ({study.method})", "quantity", "value")
    t.add_row("parameters", "; ".join(f"{p.name}: {label(p.name)}" for p in study.parameters))
    t.add_row("designs", ", ".join(f"{k} {v}" for k, v in counts.items() if v or k == "ok"))
    t.add_row("time (this run)", f"{elapsed:.3g} s")
    if counts["ok"]:
        for by, u in (("margin", ""), ("critical_thrust", "N")):
            if by in res.dataset:
                best = res.best(by)
                where = ", ".join(f"{k} = {_fmt(v, unit(k) if unit(k) not in (None, '1') else '')}"
                                  for k, v in best["parameters"].items())
                text = _fmt(best["value"], u)
                if best["lower_bound"]:
                    text = f">= {text}: {best['warning']},"
                t.add_row(f"largest {by}", f"{text} at {where}")
                break
    t.add_row("store", str(out))
    for w in written:
        t.add_row("exported", w)
    console().print(t)
    failed = res.dataset["status"].values > 0
    if failed.any():
        first = res.dataset["message"].values[failed][0]
        click.echo(f"impstab: {int(failed.sum())} designs failed (see 'status' and 'message'); first: {first}", err=True)


def _parse_at(items: tuple[str, ...]) -> dict[str, object]:
    out: dict[str, object] = {}
    for item in items:
        if "=" not in item:
            raise ModelError("--at", item, "must be PATH=VALUE, e.g. mount_rings[0].count=4")
        key, val = item.split("=", 1)
        try:
            out[key.strip()] = float(val)
        except ValueError:
            out[key.strip()] = val.strip()
    return out


@click.command("map")
@click.argument("store", type=click.Path())
@click.option("--x", "x", default=None, help="parameter path on the horizontal axis (default: the first)")
@click.option("--y", "y", default=None, help="parameter path on the vertical axis (default: the second)")
@click.option("--value", default="critical_thrust", show_default=True, help="output to colour: critical_thrust, margin, ...")
@click.option("--at", "at", multiple=True, help="value of another grid parameter, PATH=VALUE (default: its first)")
@click.option("-o", "--output", default=None, type=click.Path(dir_okay=False),
              help="figure file, .png, .svg or .pdf; default STORE-map.png")
@click.option("--dpi", type=float, default=None, help="resolution of a PNG figure (default 150; SVG and PDF are vector)")
def map_cmd(store: str, x: str | None, y: str | None, value: str, at: tuple[str, ...], output: str | None,
            dpi: float | None) -> None:
    """Draw the stability map of the study in STORE (PNG, SVG or PDF by the suffix)."""
    from ..plot.save import check_figure_path
    from ..studies import open_study

    out = Path(output) if output else Path(str(Path(store)).rstrip("/\\").removesuffix(".zarr") + "-map.png")
    check_figure_path(out)
    check_number("--dpi", dpi, positive=True)
    res = open_study(store)
    draw_and_save(lambda: res.plot(x=x, y=y, value=value, at=_parse_at(at)), out, dpi)
    console().print(f"wrote {out}")


commands = [sweep_cmd, map_cmd]
