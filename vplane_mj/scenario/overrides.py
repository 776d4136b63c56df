"""`--set KEY=VALUE` overrides applied to a parsed scenario document (docs/command-line.md).

A key is a dotted path with optional indices (`world.obstacles[0].yaw_deg`, or
`world.obstacles.0.yaw_deg`); a value is a TOML value, or a bare string when it is not
one. Missing tables are created; the document is then validated exactly like a file, and
an error at a key an override set names the override (`--set KEY`, `--seed`), not the file.
"""

from __future__ import annotations

import re
import tomllib
from dataclasses import dataclass
from typing import Any

from vplane_mj.scenario.fields import Invalid, join_key, type_name

SET_OPTION = "--set"
"""The command line's option of an override given as `KEY=VALUE` text."""
API_OPTION = "overrides"
"""The Python API's argument of an override given as `KEY=VALUE` text."""


@dataclass(frozen=True)
class Override:
    """One `KEY=VALUE` override and the option that gave it, which its errors name: `--set`
    (the command line's), `overrides` (text given to the Python API), or an option that
    stands for one key (`--seed`)."""

    text: str
    option: str = SET_OPTION

    @classmethod
    def of(cls, override: str | Override) -> Override:
        """An override given as an Override, or as text to the Python API, as an Override."""
        return override if isinstance(override, Override) else cls(override, API_OPTION)

    def origin(self, key: str) -> str:
        """How an error at `key` (the key this override set, or one inside it) names it."""
        if self.option in (SET_OPTION, API_OPTION):
            return f"{self.option} {key}".rstrip()
        return self.option


_KEY_SEGMENT = re.compile(r"([A-Za-z0-9_-]+)((?:\[[0-9]{1,9}\])*)")
"""One dotted part of a --set key: a bare key, then optional [N] indices."""


def _parse_key(key: str) -> list[str | int]:
    """`a.b[2].c` or `a.b.2.c` -> ["a", "b", 2, "c"] / ["a", "b", "2", "c"]."""
    tokens: list[str | int] = []
    for part in key.split("."):
        match = _KEY_SEGMENT.fullmatch(part)
        if match is None:
            raise Invalid(key, f"malformed key segment {part!r}")
        tokens.append(match[1])
        tokens.extend(int(index) for index in re.findall(r"[0-9]+", match[2]))
    return tokens


def _parse_value(text: str) -> Any:
    """A --set VALUE as a TOML value, or the text itself as a string when it is not one."""
    text = text.strip()
    try:
        parsed = tomllib.loads(f"v = {text}")
    except (ValueError, RecursionError):
        return text
    return parsed["v"] if parsed.keys() == {"v"} else text


def _index(token: str | int, array: list, where: str, key: str) -> int:
    """The array index `token` names, within range."""
    if isinstance(token, str):
        if not token.isdigit():
            raise Invalid(key, f"{where} is an array, index it like {where}[0]")
        token = int(token)
    if token >= len(array):
        reason = f"index {token} is out of range ({where} has length {len(array)})"
        raise Invalid(key, reason)
    return token


def _slot(node: Any, token: str | int, where: str, key: str) -> tuple[str | int, str]:
    """Where `token` points inside `node` (key or index), and that place's key path."""
    if isinstance(node, list):
        index = _index(token, node, where, key)
        return index, f"{where}[{index}]"
    if isinstance(node, dict) and isinstance(token, str):
        return token, join_key(where, token)
    raise Invalid(key, f"{where} is a {type_name(node)}, it cannot be indexed")


def apply_override(doc: dict[str, Any], text: str) -> str:
    """Apply one `KEY=VALUE` of --set to the parsed document, creating missing tables; the
    key path it set, as errors name keys (`world.obstacles[0].yaw_deg`)."""
    key, sep, value = text.partition("=")
    key = key.strip()
    if not sep:
        raise Invalid(key, "expected KEY=VALUE")
    if not key:
        raise Invalid("", f"the key before '=' is empty in {text!r}")
    tokens = _parse_key(key)
    node: Any = doc  # a table or an array on the way down the key's path
    where = ""
    for token in tokens[:-1]:
        slot, where = _slot(node, token, where, key)
        if isinstance(node, dict) and slot not in node:
            node[slot] = {}
        node = node[slot]
    slot, where = _slot(node, tokens[-1], where, key)
    node[slot] = _parse_value(value)
    return where
