"""The code's shape: short functions, and the package's layers as pyproject.toml declares them."""

import ast
from pathlib import Path

import vplane_mj

MAX_FUNCTION_LINES = 80
PACKAGE = Path(vplane_mj.__file__).parent


def test_no_function_is_longer_than_80_lines():
    long = []
    for path in sorted(PACKAGE.rglob("*.py")):
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if isinstance(node, ast.FunctionDef | ast.AsyncFunctionDef):
                lines = node.end_lineno - node.lineno + 1
                if lines > MAX_FUNCTION_LINES:
                    long.append(
                        f"{path.relative_to(PACKAGE.parent)}:{node.lineno} {node.name} ({lines} lines)"
                    )
    assert not long, "functions longer than 80 lines:\n" + "\n".join(long)


def test_at_most_nine_modules_stand_at_the_top_of_the_package():
    """The entry points, the API's two modules, and the bottom layers (errors, files, terminal,
    version): everything else lives in a package of its concern."""
    top = sorted(path.name for path in PACKAGE.glob("*.py"))
    assert len(top) <= 9, top
