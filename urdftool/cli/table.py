"""Printing rich tables of any size. rich measures and renders every cell through its generic
renderable machinery (~100 µs a cell): a 10k-joint ``limits`` table took 5x its JSON. A table
of more than ``BIG`` cells is drawn here instead, in one pass at its natural width, with the same
box, padding, justification, title and styles as rich (``tests/test_scale.py`` compares the
two); smaller tables are printed by rich itself (it also folds them to a narrow terminal)."""

from __future__ import annotations

BIG = 2000  # cells; below, rich prints the table (every feature of it, folding included)


def drawn(table):
    """What to print for ``table``: itself, or for a big one a ``_Drawn`` of it (at its
    natural width even when wider than the console: folding 10k rows to a terminal's width
    helps no one)."""
    if len(table.columns) * (table.row_count + 1) > BIG and _supported(table):
        return _Drawn(table)
    return table


def _supported(table) -> bool:
    """Whether the table uses only what ``_Drawn`` draws (the options urdftool's tables use)."""
    return (table.box is not None and table.show_edge and table.show_header
            and not table.show_footer and not table.show_lines and not table.caption
            and table.padding == (0, 1, 0, 1) and table.pad_edge and not table.collapse_padding
            and not table.expand and table.width is None and not table.row_styles
            and not table.leading and table.style in (None, "", "none")
            and table.border_style in (None, "", "none")
            and all(c.width is None and c.min_width is None and c.max_width is None
                    and c.ratio is None and not c.style and c.vertical == "top"
                    and all(isinstance(cell, str) for cell in c._cells)
                    and isinstance(c.header, str) for c in table.columns))


class _Drawn:
    """A rich renderable drawing a ``Table`` as ``Table`` does, without measuring cells
    through rich: widths are the widest line of each column."""

    def __init__(self, table):
        self.table = table

    def __rich_console__(self, console, options):
        from rich.cells import cell_len
        from rich.segment import Segment

        table = self.table
        box = table.box.substitute(options, safe=table.safe_box if table.safe_box is not None
                                   else console.safe_box)
        header_style = console.get_style(table.header_style or "")

        memo: dict[str, list] = {}  # styled cells recur (every row's "ok" verdict)

        def lines_of(markup: str, style):
            """[(plain, segments or None)] of a cell: segments only when styled."""
            if "[" not in markup and ":" not in markup and not style:
                return [(line, None) for line in markup.split("\n")]
            if not style and markup in memo:
                return memo[markup]
            text = console.render_str(markup, highlight=False) if isinstance(markup, str) \
                else markup
            if style:
                text.stylize(style)
            out = []
            for line in text.split("\n", allow_blank=True):
                segments = list(line.render(console)) if line.spans or line.style else None
                out.append((line.plain, segments))
            if not style:
                memo[markup] = out
            return out

        columns = table.columns
        grid = [[lines_of(c.header, header_style + console.get_style(c.header_style or ""))
                 for c in columns]]
        grid += [[lines_of(cell, None) for cell in row] for row in zip(*(c._cells for c in columns))]
        widths = [0] * len(columns)
        for row in grid:
            for i, cell in enumerate(row):
                for plain, _ in cell:
                    width = cell_len(plain)
                    widths[i] = max(widths[i], width)
        padded = [w + 2 for w in widths]
        table_width = sum(padded) + len(columns) + 1

        if table.title:
            title = console.render_str(table.title, style=console.get_style("table.title")
                                       + console.get_style(table.title_style or ""),
                                       highlight=False) \
                if isinstance(table.title, str) else table.title
            yield from console.render(title, options.update(
                width=table_width, justify=table.title_justify, height=None))
        new_line = Segment.line()
        yield Segment(box.get_top(padded))
        yield new_line
        justify = [c.justify for c in columns]
        for index, row in enumerate(grid):
            left, vertical, right = (box.head_left, box.head_vertical, box.head_right) \
                if index == 0 else (box.mid_left, box.mid_vertical, box.mid_right)
            height = max(len(cell) for cell in row)
            for line_no in range(height):
                plain_parts = [left]
                styled = []
                for i, cell in enumerate(row):
                    if line_no < len(cell):
                        plain, segments = cell[line_no]
                    else:
                        plain, segments = "", None
                    excess = widths[i] - cell_len(plain)
                    how = justify[i]
                    if how == "right":
                        before, after = excess, 0
                    elif how == "center":
                        before, after = excess // 2, excess - excess // 2
                    else:
                        before, after = 0, excess
                    if segments is None:
                        plain_parts.append(" " * (before + 1) + plain + " " * (after + 1))
                    else:
                        styled.append((len(plain_parts), before, segments, after))
                        plain_parts.append(None)
                    plain_parts.append(vertical if i < len(row) - 1 else right)
                if not styled:
                    yield Segment("".join(plain_parts))
                else:
                    pending = []
                    slots = {slot: rest for slot, *rest in styled}
                    for slot, part in enumerate(plain_parts):
                        if part is not None:
                            pending.append(part)
                            continue
                        before, segments, after = slots[slot]
                        pending.append(" " * (before + 1))
                        yield Segment("".join(pending))
                        pending = []
                        yield from segments
                        pending.append(" " * (after + 1))
                    yield Segment("".join(pending))
                yield new_line
            if index == 0:
                yield Segment(box.get_row(padded, "head", edge=True))
                yield new_line
        yield Segment(box.get_bottom(padded))
        yield new_line
