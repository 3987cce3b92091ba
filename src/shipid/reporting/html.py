"""A self-contained HTML report of a model and its validation: one file, figures embedded (PNG in
base64), tables from pandas, the model's equations with the standard errors of its coefficients,
the IMO criteria where the logs (or the model's manoeuvres) speak to them."""

from __future__ import annotations

import base64
import html
import io
from collections.abc import Mapping, Sequence
from pathlib import Path

import pandas as pd

from shipid import __version__


def _figure_html(draw, png: bytes | None = None) -> str:
    """An <img> tag of ``png``, or of what ``draw(buffer)`` (a plot function writing a PNG)
    draws when there is none."""
    if png is None:
        buf = io.BytesIO()
        draw(buf)
        png = buf.getvalue()
    data = base64.b64encode(png).decode("ascii")
    return f'<img src="data:image/png;base64,{data}" alt="figure" style="max-width:100%">'


def _table(df: pd.DataFrame | None, floatfmt: str = "{:.4g}") -> str:
    if df is None or len(df) == 0:
        return "<p><em>none</em></p>"
    return df.to_html(index=False, float_format=lambda x: floatfmt.format(x), na_rep="–",
                      border=0, classes="t")  # fmt: skip


STYLE = """body{font-family:sans-serif;max-width:1200px;margin:2em auto;color:#222}
table.t{border-collapse:collapse;font-size:13px;margin:0.5em 0 1.5em}
table.t td,table.t th{border-bottom:1px solid #ddd;padding:3px 8px;text-align:right}
table.t th{background:#f3f3f3} pre{background:#f6f6f6;padding:1em;overflow-x:auto}
h2{border-bottom:2px solid #ccc;padding-bottom:3px}.warn{color:#a40}"""


def _model_text(model, std_errors) -> str:
    """The model's equations; a reference ship (``shipid validate VESSEL``), what it is."""
    if hasattr(model, "equations"):
        return model.equations(std_errors=std_errors)
    text = (f"reference ship {model.name}: {model.source or 'shipid.vessels'}; Lpp "
            f"{model.length:g} m, approach {model.approach_speed:.4g} m/s, positive rudder to "
            f"{model.rudder_positive}")
    from shipid.vessels.mmg import MMGDynamics

    dyn = model.dynamics
    ref = getattr(dyn, "reference", dyn)  # a corrected ship's, or the ship's own
    if isinstance(ref, MMGDynamics):  # an MMG ship: its coefficients, as its file holds them
        from shipid.vessels.mmg_file import document_of

        doc = document_of(ref.c)
        text += ("\npropeller: " + ("each log's measured rate (rps: logs), trimmed "
                                    f"{ref.n_prop:.4g} rps for the approach" if ref.follow_rps
                                    else f"{ref.n_prop:.4g} rps"))  # fmt: skip
        for group in ("hull", "propeller", "rudder"):
            text += f"\n{group}: " + ", ".join(f"{k} {v:.6g}" for k, v in doc[group].items())
    correction = getattr(dyn, "correction", None)  # shipid correct's
    return text if correction is None else f"{text}\nits correction:\n{correction.equations()}"


def validation_report(
    model,
    validations: Sequence,
    logs: Sequence[pd.DataFrame],
    title: str,
    std_errors: Mapping | None = None,
    std_errors_label: str = "LS-SVM linear fit",
    criteria: pd.DataFrame | None = None,
    warnings: Sequence[str] = (),
    residuals: Mapping[str, Mapping] | None = None,
    figures: Mapping[str, Mapping[str, bytes]] | None = None,
    tied: pd.DataFrame | None = None,
    tied_runs: Mapping[str, Mapping[str, pd.DataFrame]] | None = None,
) -> str:
    """The HTML text of the report. ``figures``: PNGs already drawn, {log name: {"fit": ...,
    "resid": ...}} (``shipid validate --plots`` shares its own); the others are drawn here.
    ``tied``: the table of the structures ``identify`` could not tell apart from the model's,
    run on the same logs (``shipid validate``), and ``tied_runs`` their free runs per log
    ({log: {structure: simulated log}}), drawn in the figures."""
    from shipid.evaluation.horizon import ENVELOPE_COLUMNS_NOTE
    from shipid.reporting import plots
    from shipid.reporting.report import (
        horizons_frame,
        indices_frame,
        metrics_frame,
        no_manoeuvre_note,
        start_spread_note,
        switch_heading_note,
    )

    good = [(v, log) for v, log in zip(validations, logs, strict=True) if v.error is None]
    parts = [f"<!doctype html><html><head><meta charset='utf-8'><title>{html.escape(title)}"
             f"</title><style>{STYLE}</style></head><body>",
             f"<h1>{html.escape(title)}</h1>",
             f"<p>shipid {__version__}. Errors are measured − simulated over the free run from "
             "each log's measured initial state, driven by its measured inputs. Fit % as "
             "MATLAB's compare (100 % perfect, 0 % no better than the mean).</p>",
             "<h2>Model</h2>", f"<pre>{html.escape(_model_text(model, std_errors))}</pre>"]
    if std_errors:
        parts.append(f"<p>± one standard error of each coefficient "
                     f"({html.escape(std_errors_label)}).</p>")
    if warnings:
        parts.append("<h2>Warnings</h2><ul>" + "".join(
            f"<li class='warn'>{html.escape(w)}</li>" for w in warnings) + "</ul>")
    parts += ["<h2>Free-run errors</h2>", _table(metrics_frame([v for v, _ in good]))]
    band = next((v.error_band for v, _ in good if v.error_band is not None), None)
    if band is not None and band.runs:
        parts += [f"<h2>The model's training {band.held_out}, each held out</h2>",
                  f"<p>Each run free on the model fitted without it (its {band.describe()}): "
                  "rms error over the log's spread, bias included (1: no better than the "
                  "log's mean), and a zig-zag's or turn's indices run closed loop.</p>",
                  _table(pd.DataFrame(band.run_rows()))]  # fmt: skip
    horizons = horizons_frame([v for v, _ in good])
    if len(horizons):
        parts += ["<h2>Predictions over a horizon</h2>",
                  "<p>Free runs restarted from the measured state every H s; rms error over "
                  "the log's spread (1 ≈ predicting its mean)"
                  + (f"; {ENVELOPE_COLUMNS_NOTE}" if "in envelope" in horizons.columns else "")
                  + ".</p>", _table(horizons)]
    failed = [v for v in validations if v.error is not None]
    if failed:
        parts.append("<ul>" + "".join(f"<li class='warn'>{html.escape(v.error)}</li>"
                                      for v in failed) + "</ul>")  # fmt: skip
    ind = indices_frame([v for v, _ in good])
    if len(ind):
        parts += ["<h2>Manoeuvring indices</h2>", _table(ind)]
        for note in (switch_heading_note([v for v, _ in good]),
                     start_spread_note([v for v, _ in good])):  # fmt: skip
            if note:
                parts.append(f"<p>{html.escape(note)}</p>".replace("\n", "<br>"))
    unjudged = no_manoeuvre_note([v for v, _ in good])
    if unjudged:
        parts.append(f"<p>{html.escape(unjudged)}</p>")
    if tied is not None and len(tied):
        parts += ["<h2>Structures the training logs could not tell apart</h2>",
                  "<p>The same logs run on the fits of the structures that tied with the model's "
                  "in identify's comparison: what the training logs left open, which logs none "
                  "was fitted to can decide.</p>", _table(tied)]  # fmt: skip
    if criteria is not None and len(criteria):
        parts += ["<h2>IMO MSC.137(76) criteria</h2>", _table(criteria)]
    for v, log in good:
        name = Path(v.name).name
        drawn = (figures or {}).get(v.name, {})
        parts += [f"<h2>{html.escape(name)}</h2>",
                  _figure_html(lambda p, v=v, log=log, name=name: plots.measured_vs_simulated(
                      log, v.simulation.log, p, name, bands=v.bands, error_band=v.error_band,
                      tied=(tied_runs or {}).get(v.name)),
                      drawn.get("fit"))]
        if residuals and v.name in residuals:
            parts.append(_figure_html(lambda p, v=v, name=name: plots.residuals(
                residuals[v.name], p, f"{name}: residual analysis"), drawn.get("resid")))
    parts.append("</body></html>")
    return "\n".join(parts)
