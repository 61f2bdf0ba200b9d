"""Ctrl-C stops a long derivation at its next step; the GIL is released."""

import _thread
import threading
import time

import pytest

import subgram

# Many cheap steps: a word of a few thousand modules rewritten a million
# times takes minutes.
LONG = """
module A(float);
derivation length: 1000000;
Axiom: A(0) A(0) A(0) A(0) A(0) A(0) A(0) A(0);
A(x) : { if (x < 12) produce A(x + 1) A(x + 1); produce A(x + 1); }
"""


def test_ctrl_c_raises_keyboard_interrupt():
    s = subgram.load(LONG)
    timer = threading.Timer(0.5, _thread.interrupt_main)
    timer.start()
    t = time.perf_counter()
    with pytest.raises(KeyboardInterrupt):
        s.derive()
    took = time.perf_counter() - t
    timer.cancel()
    assert took < 10, took


def test_gil_is_released():
    s = subgram.load(LONG)
    ticks = []
    done = threading.Event()

    def tick():
        while not done.is_set():
            ticks.append(time.perf_counter())
            time.sleep(0.01)

    th = threading.Thread(target=tick)
    th.start()
    s.derive(150)
    done.set()
    th.join()
    assert len(ticks) > 5


def _interrupted(call):
    """Runs `call` with Ctrl-C half a second in: KeyboardInterrupt comes
    while the run is still under way (long before it would end), and the
    next run is not stopped by it."""
    timer = threading.Timer(0.5, _thread.interrupt_main)
    timer.start()
    t = time.perf_counter()
    with pytest.raises(KeyboardInterrupt):
        call()
    took = time.perf_counter() - t
    timer.cancel()
    return took


def test_ctrl_c_stops_a_render():
    # The picture of the derivation above: minutes of deriving first.
    s = subgram.load(LONG)
    took = _interrupted(lambda: s.render(timeout=None))
    assert took < 10, took
    # The stop is over: a short run goes through.
    assert subgram.load(LONG).derive(3) is not None


def test_ctrl_c_stops_a_subdivision():
    import numpy as np

    # A 64 x 64 grid of quads, Catmull-Clark 6 times: 16.7 million faces,
    # well over half a second.
    n = 64
    ij = np.array([(i, j) for j in range(n + 1) for i in range(n + 1)], dtype=float)
    v = np.column_stack([ij, np.zeros(len(ij))])
    f = np.array(
        [
            [j * (n + 1) + i, j * (n + 1) + i + 1, (j + 1) * (n + 1) + i + 1, (j + 1) * (n + 1) + i]
            for j in range(n)
            for i in range(n)
        ]
    )
    took = _interrupted(lambda: subgram.subdivide(v, f, "catmull-clark", steps=6))
    assert took < 10, took
