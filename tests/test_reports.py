"""The benchmark reports (benchmarks/*_report.md) are what the benchmark scripts write from the committed JSON:
regenerating one gives the committed file byte for byte (so a report cannot drift from its data)."""
import importlib.util
import json
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent


@pytest.mark.parametrize("name", ["taylor", "pressing", "cutting"])
def test_report_is_generated_from_the_json(name):
    spec = importlib.util.spec_from_file_location(f"bench_{name}", ROOT / "benchmarks" / f"{name}.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    records = json.loads((ROOT / "benchmarks" / f"{name}.json").read_text())
    assert mod.report(records) == (ROOT / "benchmarks" / f"{name}_report.md").read_text()
