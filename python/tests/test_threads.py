"""The GIL is released while jointrom computes: two reduced runs in two threads overlap; Ctrl-C
and a raising progress callback stop a run; the binding's own cost is small."""

import _thread
import threading
import time

import pytest

import jointrom as jr


def test_two_reduced_runs_overlap_in_time(bar_tvd):
    # Each run's progress callback is called from its own thread with the time reached; the
    # runs overlap when each saw the other in progress (0 < t < end) between its own ticks.
    end = 0.2
    ticks = {0: [], 1: []}
    spans = {}
    barrier = threading.Barrier(2)

    def work(k):
        barrier.wait()
        t0 = time.perf_counter()
        bar_tvd.transient(
            end_time=end, progress=lambda t, e: ticks[k].append((time.perf_counter(), t))
        )
        spans[k] = (t0, time.perf_counter())

    threads = [threading.Thread(target=work, args=(k,)) for k in (0, 1)]
    for th in threads:
        th.start()
    for th in threads:
        th.join()
    mid = {k: [w for w, t in ticks[k] if 0.0 < t < end] for k in ticks}
    assert mid[0] and mid[1], f"too short to see progress: {ticks}"
    # While run 0 was in the middle of its integration, run 1 was too (and vice versa).
    assert any(mid[1][0] <= w <= mid[1][-1] for w in mid[0]), (mid, spans)
    assert any(mid[0][0] <= w <= mid[0][-1] for w in mid[1]), (mid, spans)
    overlap = min(spans[0][1], spans[1][1]) - max(spans[0][0], spans[1][0])
    print(f"spans {spans}, overlap {overlap:.3f} s")
    assert overlap > 0.5 * min(b - a for a, b in spans.values())


def test_call_overhead_is_small(bar_tvd):
    bar_tvd.transient(end_time=0.02)
    ratios = []
    for _ in range(5):
        t0 = time.perf_counter()
        run = bar_tvd.transient(end_time=0.02)
        elapsed = time.perf_counter() - t0
        ratios.append((elapsed - run.total_s) / elapsed)
    best = min(ratios)
    print(f"binding overhead of a short reduced run: {100 * best:.2f} % (runs: {ratios})")
    assert best < 0.05


def test_ctrl_c_raises_keyboard_interrupt(bar):
    timer = threading.Timer(0.3, _thread.interrupt_main)
    timer.start()
    t0 = time.perf_counter()
    with pytest.raises(KeyboardInterrupt):
        # The full model: seconds of integration, stopped within a tick of the signal.
        bar.transient(end_time=0.2)
    assert time.perf_counter() - t0 < 2.0
    timer.join()


def test_progress_callback_that_raises_stops_the_run(bar):
    calls = []

    def progress(t, end):
        calls.append(t)
        if len(calls) == 2:
            raise RuntimeError("enough")

    t0 = time.perf_counter()
    with pytest.raises(RuntimeError, match="enough"):
        bar.transient(end_time=0.2, progress=progress)
    assert time.perf_counter() - t0 < 2.0
    assert all(0.0 <= t <= 0.2 for t in calls)


def test_interrupted_export_leaves_no_file(bar, tmp_path):
    # An interrupted build writes nothing: files are written only after the work, atomically.
    timer = threading.Timer(0.2, _thread.interrupt_main)
    timer.start()
    out = tmp_path / "rom.json"
    with pytest.raises(KeyboardInterrupt):
        bar.reduce(tolerance=1e-3).save(out)
    timer.join()
    assert not out.exists()
    assert list(tmp_path.iterdir()) == []
