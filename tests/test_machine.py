import re
from pathlib import Path

from experiments.core import machine


def test_transparent_hugepages_reads_the_selected_modes(tmp_path):
    (tmp_path / "enabled").write_text("always [madvise] never\n")
    (tmp_path / "defrag").write_text("always defer defer+madvise [madvise] never\n")
    assert machine.transparent_hugepages(tmp_path) == {"enabled": "madvise", "defrag": "madvise"}


def test_transparent_hugepages_without_the_files_is_empty(tmp_path):
    assert machine.transparent_hugepages(tmp_path / "missing") == {}


def test_free_page_reporting_order_reads_the_parameter_or_is_none(tmp_path):
    (tmp_path / "page_reporting_order").write_text("9\n")
    assert machine.free_page_reporting_order(tmp_path) == 9
    assert machine.free_page_reporting_order(tmp_path / "missing") is None


def test_machine_info_records_cpu_caches_pages_versions_and_commit():
    info = machine.machine_info()
    assert info["cores"] >= 1 and info["cpu"]
    assert set(info["transparent_hugepages"]) <= {"enabled", "defrag"}
    assert info["free_page_reporting_order"] == machine.free_page_reporting_order()
    assert "numpy" in info["versions"] and "numba" in info["versions"]
    if (Path(machine.__file__).parents[1] / ".git").exists():  # a checkout, not an export
        assert re.fullmatch(r"[0-9a-f]{40}", info["commit"])
