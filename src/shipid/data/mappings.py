"""Hand-written YAML and JSON files read strictly: a key given twice is an error.

PyYAML and the json module both keep the last of a key given twice without a word: a
particulars file with ``length: 3`` and, further down, ``length: 4`` judged the IMO criteria at
4 m. Particulars, MMG files, study specifications and model files are read here.
"""

from __future__ import annotations

import json
from collections.abc import Callable

from shipid.errors import ShipidError


class DuplicateKeyError(ValueError):
    """A mapping with a key given twice (the message names the key and, for YAML, its line)."""


def load_yaml(text: str):
    """``yaml.safe_load`` of ``text``, refusing a mapping that gives a key twice
    (``DuplicateKeyError``; other errors are PyYAML's)."""
    import yaml

    class StrictLoader(yaml.SafeLoader):
        pass

    def mapping(loader, node, deep=False):
        seen = set()
        for key_node, _ in node.value:
            key = loader.construct_object(key_node, deep=deep)
            try:
                repeated = key in seen
            except TypeError:  # an unhashable key: PyYAML's own error follows
                break
            if repeated:
                raise DuplicateKeyError(f"{key!r} is given twice (line "
                                        f"{key_node.start_mark.line + 1})")  # fmt: skip
            seen.add(key)
        return loader.construct_mapping(node, deep=deep)

    StrictLoader.add_constructor(yaml.resolver.BaseResolver.DEFAULT_MAPPING_TAG, mapping)
    return yaml.load(text, Loader=StrictLoader)  # noqa: S506 - a SafeLoader subclass


def _pairs(pairs):
    out = {}
    for key, value in pairs:
        if key in out:
            raise DuplicateKeyError(f"{key!r} is given twice")
        out[key] = value
    return out


def load_json(text: str, parse_constant: Callable | None = None):
    """``json.loads`` of ``text``, refusing an object that gives a key twice
    (``DuplicateKeyError``)."""
    return json.loads(text, object_pairs_hook=_pairs, parse_constant=parse_constant)


def duplicate_key_error(path, exc: DuplicateKeyError) -> ShipidError:
    """The one-line error for a file whose mapping gives a key twice."""
    return ShipidError(f"{path}: {exc} (a key given twice keeps one of its values without a "
                       "word: give each once)")
