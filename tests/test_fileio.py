"""Strict JSON in one place: every JSON file and --json output goes through fileio.json_text."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest

from locust.fileio import atomic_write_json, json_text


def test_numbers_json_cannot_hold_become_null_everywhere_in_the_tree(tmp_path):
    obj = {"a": math.nan, "b": [1.5, math.inf, -math.inf, (np.float64("nan"), np.float32(2.5))],
           "c": {"d": np.array([1.0, np.nan]), "e": np.int64(7), "f": Path("x/y"), "g": None, "h": True}}
    text = json_text(obj)
    assert text.endswith("\n") and "NaN" not in text and "Infinity" not in text
    assert json.loads(text) == {"a": None, "b": [1.5, None, None, [None, 2.5]],
                                "c": {"d": [1.0, None], "e": 7, "f": "x/y", "g": None, "h": True}}
    path = atomic_write_json(tmp_path / "out.json", obj)
    assert path.read_text() == text
    with pytest.raises(TypeError, match="not JSON serialisable: object"):
        json_text({"x": object()})
