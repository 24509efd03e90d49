"""A report's table as text: its cells as the Markdown shows them, and the whole table fitted
to a terminal's width (what ``grainview report`` and ``study`` print)."""

from __future__ import annotations

import numpy as np
import pandas as pd


def format_cell(value) -> str:
    """A table cell as the Markdown and the terminal show it: finite floats to 3 decimals,
    anything else as text."""
    return f"{value:.3f}" if isinstance(value, (float, np.floating)) and np.isfinite(value) else str(value)


def terminal_table(table: pd.DataFrame, width: int | None = None, column_width: int = 24) -> str:
    """``table`` as text that fits a terminal ``width`` characters wide (default: the
    terminal's, :func:`shutil.get_terminal_size`), cells rounded as in the Markdown
    (:func:`format_cell`).

    Text longer than ``column_width`` wraps within its cell (headers too), and the columns
    that do not fit beside the row names go to further blocks below, each repeating the row
    names. Returns the text, lines joined by newlines."""
    import shutil
    import textwrap

    width = max(int(width or shutil.get_terminal_size().columns), 30)
    gap = "  "
    names = [str(idx) for idx in table.index]
    name_width = min(max([len(n) for n in names] + [1]), max(12, width // 3))
    room = width - name_width - len(gap)
    cells = {column: [format_cell(v) for v in table[column]] for column in table.columns}
    widths = {column: max(1, min(max([len(str(column))] + [len(c) for c in cells[column]]), column_width, room))
              for column in table.columns}

    def wrap(text, size):
        return textwrap.wrap(text, size, break_long_words=True, break_on_hyphens=False) or [""]

    blocks, block, used = [], [], 0
    for column in table.columns:
        needed = widths[column] + (len(gap) if block else 0)
        if block and used + needed > room:
            blocks.append(block)
            block, used, needed = [], 0, widths[column]
        block.append(column)
        used += needed
    if block:
        blocks.append(block)

    lines = []
    for b, columns in enumerate(blocks):
        if b:
            lines.append("")
        rows = [(" " * name_width, [wrap(str(c), widths[c]) for c in columns])]
        rows += [(names[r], [wrap(cells[c][r], widths[c]) for c in columns]) for r in range(len(names))]
        for name, parts in rows:
            name_lines = wrap(name, name_width) if name.strip() else [""]
            height = max([len(name_lines)] + [len(p) for p in parts])
            for k in range(height):
                left = name_lines[k] if k < len(name_lines) else ""
                line = left.ljust(name_width) + gap + gap.join(
                    (p[k] if k < len(p) else "").ljust(widths[c]) for p, c in zip(parts, columns))
                lines.append(line.rstrip())
    return "\n".join(lines)
