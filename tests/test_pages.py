"""lfqt.pages: mappings advised for or against huge pages, their pages past
a prefix given back, and the detection of a host that takes free pages
back."""
import numpy as np
import pytest

from conftest import smaps_entry
from lfqt import pages, workspace


def test_give_back_keeps_the_pages_before_and_frees_those_after():
    T = workspace.Pool().empty(6_000_000, np.int32)
    T[:] = np.arange(len(T), dtype=np.int32)
    before = smaps_entry(T)
    buf, offset = pages.mapping_of(T[10:])
    assert offset == 40 and pages.mapping_of(T) == (buf, 0)
    assert pages.mapping_of(np.arange(5)) is None
    pages.give_back(buf, 4_000_012 + 1)  # rounded up to a page: bytes before it are kept
    assert np.array_equal(T[:1_000_003], np.arange(1_000_003, dtype=np.int32))
    assert not T[1_000_000 + 1024:].any()  # read back as zeros
    after = smaps_entry(T)
    if before is not None and after is not None:
        assert after[0] < before[0] / 2  # 4 MB of 24 MB are still in use


def test_give_back_up_to_a_stop_frees_only_the_whole_pages_before_it():
    T = workspace.Pool().empty(6_000_000, np.int32)
    T[:] = np.arange(len(T), dtype=np.int32)
    buf, _ = pages.mapping_of(T)
    pages.give_back(buf, 0, 4_000_012 + 1)  # rounded down to a page: bytes after it are kept
    assert not T[:1_000_000 - 1024].any()  # read back as zeros
    assert np.array_equal(T[1_000_003:], np.arange(1_000_003, len(T), dtype=np.int32))
    pages.give_back(buf, 4096, 4096 + 4095)  # less than a whole page: nothing
    assert T[1_000_003] == 1_000_003


@pytest.mark.parametrize("huge, flag", [(True, "hg"), (False, "nh")])
def test_large_arrays_get_a_mapping_advised_as_asked(huge, flag):
    a = workspace.Pool().empty((1 << 19, 3), np.int32, huge)  # a fresh mapping
    assert a.shape == (1 << 19, 3) and a.dtype == np.int32 and a.flags.c_contiguous
    a[:] = 7  # writable
    assert int(a.sum()) == 7 * a.size
    found = smaps_entry(a)
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
def test_huge_pages_only_on_a_host_that_keeps_free_pages(monkeypatch, host_takes):
    monkeypatch.setattr(pages, "host_takes_free_pages", lambda: host_takes)
    assert pages.huge_pays() is (not host_takes)


@pytest.mark.parametrize("host_takes", [True, False])
def test_a_fresh_mapping_of_the_pool_follows_huge_pays(monkeypatch, host_takes):
    monkeypatch.setattr(pages, "host_takes_free_pages", lambda: host_takes)
    asked = []
    real = pages.mapping
    monkeypatch.setattr(pages, "mapping", lambda nbytes, huge: asked.append(huge) or real(nbytes, huge))
    pool = workspace.Pool()
    a = pool.empty(workspace.SMALLEST * 3, np.uint8)
    assert asked == [not host_takes] and a.nbytes == workspace.SMALLEST * 3
