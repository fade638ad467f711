"""lfqt.pages: mappings advised for or against huge pages, prefixes that give
back the rest, and the detection of a host that takes free pages back."""
import re

import numpy as np
import pytest

from lfqt import pages, workspace


def _mapping(arr):
    """(resident kB, VmFlags) of the mapping that holds arr, from Linux's
    smaps; None where that is not available."""
    start = arr.__array_interface__["data"][0]
    try:
        text = open("/proc/self/smaps").read()
    except OSError:
        return None
    for m in re.finditer(r"^([0-9a-f]+)-([0-9a-f]+) .*?\nRss:\s+(\d+) kB.*?\nVmFlags:([^\n]*)",
                         text, re.M | re.S):
        lo, hi = int(m.group(1), 16), int(m.group(2), 16)
        if lo <= start < hi:
            return int(m.group(3)), m.group(4).split()
    return None


def test_keep_prefix_keeps_the_rows_and_gives_back_the_rest():
    T = workspace.empty(6_000_000, np.int32)
    T[:] = np.arange(len(T), dtype=np.int32)
    before = _mapping(T)
    kept = pages.keep_prefix(T, 1_000_003)
    assert np.array_equal(kept, np.arange(1_000_003, dtype=np.int32))
    after = _mapping(T)
    if before is not None and after is not None:
        assert after[0] < before[0] / 2  # 4 MB of 24 MB are still in use


@pytest.mark.parametrize("huge, flag", [(True, "hg"), (False, "nh")])
def test_large_arrays_get_a_mapping_advised_as_asked(huge, flag):
    a = workspace.Pool().empty((1 << 19, 3), np.int32, huge)  # a fresh mapping
    assert a.shape == (1 << 19, 3) and a.dtype == np.int32 and a.flags.c_contiguous
    a[:] = 7  # writable
    assert int(a.sum()) == 7 * a.size
    found = _mapping(a)
    if found is None:
        pytest.skip("no /proc/self/smaps here")
    assert flag in found[1] and ({"hg", "nh"} - {flag}).isdisjoint(found[1])


def _device(root, name, device, features):
    d = root / name
    d.mkdir()
    (d / "device").write_text(f"0x{device:04x}\n")
    (d / "features").write_text(features + "\n")


def test_a_balloon_that_reports_free_pages_is_detected(tmp_path):
    bits = "0110010100000000000000000000000010000000"  # bit 5 set, as on our VMs
    assert not pages.host_takes_free_pages(str(tmp_path / "missing"))
    _device(tmp_path, "virtio1", 0x0002, bits)  # a block device with the same bits
    assert not pages.host_takes_free_pages(str(tmp_path))
    _device(tmp_path, "virtio0", 0x0005, bits[:5] + "0" + bits[6:])  # a balloon, no reporting
    assert not pages.host_takes_free_pages(str(tmp_path))
    _device(tmp_path, "virtio2", 0x0005, bits)
    assert pages.host_takes_free_pages(str(tmp_path))


@pytest.mark.parametrize("host_takes", [True, False])
def test_huge_pages_pay_for_arrays_reused_soon_or_on_a_host_that_keeps_free_pages(
        monkeypatch, host_takes):
    monkeypatch.setattr(pages, "host_takes_free_pages", lambda: host_takes)
    assert pages.huge_pays(pages.SOON_REUSED)
    assert pages.huge_pays(1 << 20)
    assert pages.huge_pays(pages.SOON_REUSED + 1) is (not host_takes)
    assert pages.huge_pays(1 << 34) is (not host_takes)
