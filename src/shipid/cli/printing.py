"""How the commands print: warnings, counts of logs, terms in Markdown tables, JSON, tables with
blanks; pandas and NumPy imported where a table is made (``--help`` imports neither)."""

from __future__ import annotations

import json
import warnings

from shipid.errors import ShipidWarning


def _count_logs(names) -> str:
    """'1 of the logs (a.csv)', '4 of the logs (a.csv, b.csv, c.csv, …)'."""
    return f"{len(names)} of the logs ({', '.join(names[:3])}{', …' if len(names) > 3 else ''})"


def _term_display(text: str) -> str:
    """A term as printed in a Markdown table cell (its bars escaped: ``\\|u\\|u``)."""
    from shipid.dynamics.terms import parse_term

    return (parse_term(text).display() or "1").replace("|", "\\|")


def _json_text(data) -> str:
    from shipid.reporting.modelfile import json_safe

    return json.dumps(json_safe(data), indent=2, ensure_ascii=False) + "\n"


def _markdown_dashed(table, fmt: str) -> str:
    """``table`` as markdown, its numbers to ``fmt`` and its blanks (NaN, None) as '–'."""
    # Mixed columns (numbers and blanks) are objects, which floatfmt leaves alone.
    table = table.map(lambda x: f"{x:{fmt}}" if isinstance(x, float) and x == x else x)
    return table.astype(object).where(table.notna(), "–").to_markdown(index=False, floatfmt=fmt)


def _warn(message: str) -> None:
    warnings.warn(message, ShipidWarning, stacklevel=2)


def _fmt_speed(u: float | None) -> str:
    return "none" if u is None else f"{u:.3g} m/s"


def _pd():
    import pandas as pd

    return pd


def _np():
    import numpy as np

    return np
