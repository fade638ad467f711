"""lfqt.calls: background work waits while a public call runs."""
import threading

from lfqt import calls


def _in_thread(target):
    t = threading.Thread(target=target, daemon=True)
    t.start()
    return t


def test_wait_idle_blocks_while_an_entry_runs_and_returns_when_it_ends():
    inside, release, waited = threading.Event(), threading.Event(), threading.Event()

    @calls.entry
    def call():
        inside.set()
        assert calls.depth() == 1
        release.wait(10)

    caller = _in_thread(call)
    assert inside.wait(10)
    waiter = _in_thread(lambda: (calls.wait_idle(), waited.set()))
    assert not waited.wait(0.3)  # the entry still runs
    release.set()
    assert waited.wait(10)
    caller.join(10), waiter.join(10)
    assert calls.depth() == 0


def test_a_cancelled_wait_returns_though_an_entry_runs():
    inside, release, stop = threading.Event(), threading.Event(), []

    @calls.entry
    def call():
        inside.set()
        release.wait(10)

    caller = _in_thread(call)
    assert inside.wait(10)
    waiter = _in_thread(lambda: calls.wait_idle(lambda: bool(stop)))
    waiter.join(0.3)
    assert waiter.is_alive()
    stop.append(True)
    calls.wake()
    waiter.join(10)
    assert not waiter.is_alive()
    release.set()
    caller.join(10)


def test_the_background_threads_own_calls_do_not_count_and_an_error_still_ends_an_entry():
    seen = []

    @calls.entry
    def call(fail=False):
        seen.append(calls.depth())
        if fail:
            raise ValueError("bad input")

    def background():
        call()  # as the preload's own triangulations
        calls.wait_idle()  # would wait for itself if they counted

    saved = calls.background
    try:
        t = threading.Thread(target=background, daemon=True)
        calls.background = t
        t.start()
        t.join(10)
        assert not t.is_alive()
    finally:
        calls.background = saved
    try:
        call(fail=True)
    except ValueError:
        pass
    calls.wait_idle()  # returns at once: the failed entry is not counted as running
    assert seen == [0, 1] and calls.depth() == 0
