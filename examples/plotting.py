"""What the examples share: matplotlib for their plots, where it is installed."""

from __future__ import annotations

from typing import Any, Optional


def pyplot() -> Optional[Any]:
    """matplotlib.pyplot drawing to files (the Agg backend), or None, said on the terminal,
    where matplotlib is not installed."""
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        print("matplotlib is not installed: no plot (pip install matplotlib)")
        return None
    return plt


def save(ax: Any, path: Any) -> None:
    """Adds `ax`'s legend and writes its figure to `path` (120 dpi), saying so."""
    ax.legend()
    ax.figure.tight_layout()
    ax.figure.savefig(path, dpi=120)
    print(f"wrote {path}")
