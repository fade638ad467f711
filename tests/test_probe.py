"""experiments.core.probe: the machine's own thread scaling.  Its numbers are
measurements of the machine, so only their form is checked here; the
kernels are checked for doing the work they claim."""
import math

import numpy as np
import pytest

from experiments.core import probe


def test_the_chase_buffer_is_one_cycle_through_every_entry():
    buf = probe._chase_buffer(4 * 1000)  # rounded down to 512 entries
    assert buf.shape == (512,)
    seen = np.zeros(512, dtype=bool)
    i = 7
    for _ in range(512):
        assert not seen[i]
        seen[i] = True
        i = buf[i]
    assert seen.all() and i == 7
    assert probe._dependent_reads(buf, 512, 7) == 7
    assert probe._dependent_reads(buf, 1, 7) == buf[7]


def test_random_reads_are_a_fixed_sequence_of_the_seed():
    buf = np.arange(1 << 12, dtype=np.int32)
    a, b = probe._random_reads(buf, 1000, 3), probe._random_reads(buf, 1000, 3)
    assert a == b != probe._random_reads(buf, 1000, 5)
    assert 0 < a < 1000 * (1 << 12)


def test_thread_scaling_gives_every_probe_at_every_count():
    work = {"compute": 20_000, "random reads": 20_000, "dependent reads": 5_000}
    out = probe.thread_scaling([2, 3], work=work, repeats=2, buffer_bytes=1 << 16)
    assert set(out) == set(probe.WORK)
    for by_t in out.values():
        assert set(by_t) == {1, 2, 3} and by_t[1] == 1.0
        assert all(math.isfinite(v) and v > 0 for v in by_t.values())


def test_thread_counts_must_be_positive():
    with pytest.raises(ValueError, match="positive"):
        probe.thread_scaling([0, 2])
