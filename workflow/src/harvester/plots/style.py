"""The figures' one style, after the paper's Figures 7, 9 and 10: measured data in grey, the
model's mean in black, uncertainty bounds shaded, every axis labelled with its unit; and the
one way a figure is written (:func:`save_figure`: atomic, one resolution).
"""

from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from matplotlib.figure import Figure  # noqa: E402

from harvester.data.fileio import atomic_path  # noqa: E402

#: Resolution of every PNG the project writes (dots per inch).
DPI = 120
#: Measured (or unfiltered) data: grey, as the paper's figures.
MEASURED = "0.6"
#: The model's mean (or the filtered data): black.
MODEL = "black"
#: Shaded bounds: the full predictive (parameters and noise) and parameters alone.
BOUNDS = {"predictive": ("tab:blue", 0.18), "parameter": ("tab:orange", 0.45)}
#: What the eye should go to: flagged windows, a reference value.
HIGHLIGHT = "tab:red"
#: Font sizes of titles, legends and footnotes.
TITLE_SIZE, LEGEND_SIZE, NOTE_SIZE = 10, 8, 7


def axis_label(quantity: str, unit: str | None) -> str:
    """'quantity (unit)', or the quantity alone for a dimensionless one."""
    return f"{quantity} ({unit})" if unit else quantity


def save_figure(fig: Figure, path: str | Path, tight: bool = True,
                rect: tuple[float, float, float, float] | None = None,
                crop: bool = False) -> Path:
    """Lay out (``tight``; ``rect`` leaves room for a footnote), write ``fig`` to ``path`` at
    :data:`DPI` (PNG unless the suffix says otherwise; ``crop``: to the drawn area),
    atomically (a reader never sees half a file), and close it."""
    path = Path(path)
    try:
        if tight:
            fig.tight_layout(rect=rect) if rect is not None else fig.tight_layout()
        with atomic_path(path) as tmp:
            fig.savefig(tmp, dpi=DPI, format=path.suffix.lstrip(".") or "png",
                        bbox_inches="tight" if crop else None)
    finally:
        plt.close(fig)
    return path
