"""Every figure takes its size and fonts from ``biped.pages.style``: no module of the project
gives a figure's size or a font size as a number of its own."""

import ast
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
# The keywords of matplotlib that size a figure or a text.
SIZES = ("figsize", "fontsize", "labelsize", "title_fontsize")


def _literal(node) -> bool:
    """A number, or a tuple or expression holding one (``(8, 6.4)``, ``4.4 * columns``); an
    index is none (``SIZE[0] * columns``)."""
    indices = {id(n.slice) for n in ast.walk(node) if isinstance(n, ast.Subscript)}
    return any(
        isinstance(n, ast.Constant) and isinstance(n.value, int | float) and id(n) not in indices
        for n in ast.walk(node)
    )


def literal_sizes(path: Path) -> list[str]:
    """``file:line keyword`` of each size given as a number in ``path`` (a keyword argument,
    or a ``"fontsize"`` key of a dict)."""
    found = []
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.keyword) and node.arg in SIZES and _literal(node.value):
            found.append(f"{path.name}:{node.value.lineno} {node.arg}")
        if isinstance(node, ast.Dict):
            for key, value in zip(node.keys, node.values, strict=True):
                if isinstance(key, ast.Constant) and key.value in SIZES and _literal(value):
                    found.append(f"{path.name}:{value.lineno} {key.value}")
    return found


def test_every_figure_takes_its_size_and_fonts_from_the_style(tmp_path):
    """No module of biped/ or validate/ sizes a figure or a font with a number (the style's
    names), and each wrong form is found."""
    modules = [p for root in ("biped", "validate") for p in sorted((ROOT / root).rglob("*.py"))]
    style = ROOT / "biped" / "pages" / "style.py"
    assert [use for path in modules for use in literal_sizes(path)] == []
    assert "FONT_NOTE = 8" in style.read_text() and "MARGINS_SIZE = (11, 5.0)" in style.read_text()
    wrong = tmp_path / "wrong.py"
    wrong.write_text(
        "fig = Figure(figsize=(4.4 * columns, SIZE[1]))\nax.legend(fontsize=8)\n"
        "ax.tick_params(labelsize=SIZE)\nax.annotate(t, **{'fontsize': 7})\n"
    )
    assert literal_sizes(wrong) == [
        "wrong.py:1 figsize",
        "wrong.py:2 fontsize",
        "wrong.py:4 fontsize",
    ]
