"""The interactive views' files in the report folder and their place in ``index.html``.

Layout (all relative to the report folder, so the page opens offline from
any copy of it)::

    interactive/plotly-<version>.min.js   plotly's browser bundle, from the plotly package (once)
    interactive/<dataset slug>.js         one dataset's figure (albot1.report.interactive)
    interactive/figures.json              the stamps of the figure cache

A dataset's script registers its figure in ``window.ALBOT1_VIEWS`` (a
``<script src>``, not a fetched JSON file: browsers refuse ``fetch`` from a
``file://`` page). The page draws a view when it scrolls into sight (a long
report holds many), and ``albot1ShowView(slug)`` draws one on demand (it
returns plotly's promise; the browser test uses it). A view's figure is
rebuilt only when its runs changed (:mod:`albot1.report.figure_cache`).
"""

from __future__ import annotations

import html
import json
from dataclasses import dataclass
from functools import partial
from pathlib import Path

from albot1.atomic import atomic_write
from albot1.report.collect import CellRecord
from albot1.report.figure_cache import FigureCache, inputs_digest
from albot1.report.interactive import MAX_POSES, dataset_figure, figure_json, write_plotly_js
from albot1.report.plots import slug
from albot1.report.tuning import record_held_in

VIEWS_DIR = "interactive"
#: Plotly's options for every view: wheel zoom, pan by dragging, no logo, fits its column.
CONFIG = {"scrollZoom": True, "responsive": True, "displaylogo": False}

#: Draws each ``div.view`` when it comes into sight; ``albot1ShowView(slug)`` draws one now (a promise).
SCRIPT = """
(function () {
  var views = window.ALBOT1_VIEWS || {};
  var config = %s;
  function show(div) {
    if (!div) { return Promise.reject(new Error("no such view")); }
    if (div.dataset.drawn) { return Promise.resolve(div); }
    var view = views[div.dataset.view];
    if (!window.Plotly || !view) {
      div.textContent = "The interactive view could not be loaded (" +
        (window.Plotly ? "its data script is missing" : "plotly.min.js is missing") + ").";
      return Promise.reject(new Error(div.textContent));
    }
    div.dataset.drawn = "1";
    return Plotly.newPlot(div, view.data, view.layout, config);
  }
  window.albot1ShowView = function (name) {
    return show(document.querySelector('div.view[data-view="' + name + '"]'));
  };
  var divs = document.querySelectorAll("div.view");
  if ("IntersectionObserver" in window) {
    var seen = new IntersectionObserver(function (entries) {
      entries.forEach(function (e) { if (e.isIntersecting) { seen.unobserve(e.target); show(e.target); } });
    }, {rootMargin: "300px"});
    divs.forEach(function (d) { seen.observe(d); });
  } else {
    divs.forEach(show);
  }
})();
"""


@dataclass(frozen=True)
class View:
    """One dataset's view: the script holding its figure, its name on the page and its notes."""

    dataset: str
    name: str
    script: Path
    notes: list[str]


def write_views(records: list[CellRecord], out: Path, colors: dict[str, str]) -> tuple[Path | None, dict[str, View]]:
    """Write plotly's bundle and each dataset's figure script; (the bundle or None, dataset -> its view)."""
    by_dataset: dict[str, list[CellRecord]] = {}
    for rec in records:
        by_dataset.setdefault(rec.cell.dataset_label, []).append(rec)
    folder = out / VIEWS_DIR
    folder.mkdir(parents=True, exist_ok=True)
    cache = FigureCache(folder)
    views: dict[str, View] = {}
    for dataset, recs in by_dataset.items():
        name = slug(dataset)
        used = {label: c for label, c in colors.items() if any(r.cell.method_label == label for r in recs)}
        # the held-in marks come from the preset files, not the runs: a changed [tuned_on] draws the view again
        held = [(r.cell.key, record_held_in(r)) for r in recs]
        digest = inputs_digest(recs, "view", dataset, MAX_POSES, sorted(used.items()), held)
        cached = cache.lookup(f"view:{dataset}", digest)
        if cached is not None and isinstance(cached.payload, list):
            views[dataset] = View(dataset, name, folder / f"{name}.js", [str(n) for n in cached.payload])
            continue
        figure = dataset_figure(recs, dataset, colors)
        if figure is None:  # no completed run: nothing to draw
            continue
        script = folder / f"{name}.js"
        body = (
            "window.ALBOT1_VIEWS = window.ALBOT1_VIEWS || {};\n"
            f"window.ALBOT1_VIEWS[{json.dumps(name)}] = {figure_json(figure)};\n"
        )
        atomic_write(script, partial(_write_text, text=body))
        views[dataset] = View(dataset, name, script, list(figure["notes"]))
        cache.store(f"view:{dataset}", digest, [script], views[dataset].notes)
    cache.save()
    bundle = write_plotly_js(folder) if views else None
    return bundle, views


def _write_text(path: Path, text: str) -> None:
    path.write_text(text, encoding="utf-8")


def view_html(view: View) -> str:
    """A dataset's view on the page: a heading, how to use it, its notes and the element plotly draws in."""
    e = html.escape
    notes = "".join(f"<li>{e(n)}</li>" for n in view.notes)
    return (
        "<h3>Interactive view</h3>"
        '<p class="notes">Drag to pan, scroll to zoom, double-click to reset; hover a pose for its index, time '
        "and absolute position error (the per-pose error whose RMSE is the table's ATE, unrounded). "
        "Click a legend entry to show or hide a trajectory or a map.</p>"
        + (f'<ul class="notes">{notes}</ul>' if notes else "")
        + f'<div class="view" data-view="{e(view.name, quote=True)}" style="min-height:640px"></div>'
    )


def views_scripts(bundle: Path | None, views: dict[str, View], rel: str) -> list[str]:
    """The ``<script>`` tags of the page's views (``rel``: the report folder's path of the views' folder)."""
    if bundle is None or not views:
        return []
    e = html.escape
    tags = [f'<script src="{e(rel)}/{e(bundle.name, quote=True)}"></script>']
    tags += [f'<script src="{e(rel)}/{e(v.script.name, quote=True)}"></script>' for v in views.values()]
    return [*tags, f"<script>{SCRIPT % json.dumps(CONFIG)}</script>"]
