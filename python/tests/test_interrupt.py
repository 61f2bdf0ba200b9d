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
