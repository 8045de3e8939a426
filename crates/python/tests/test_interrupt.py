"""Ctrl-C (SIGINT) stops a running simulate or simulate_batch within a
fraction of a second with KeyboardInterrupt (the runs poll for it while the
GIL is released), and no thread of the run is left behind."""

import _thread
import os
import signal
import threading
import time

import numpy as np
import pytest

import hydrocyl

#: A run of several seconds at least (without the fix the interrupt came
#: only when it ended): rk4 with a 1 us step over LONG_S of a sine command
#: (8 million steps, inside the step budget of 10 million).
LONG_S = 8.0
LONG = dict(solver="rk4", rk4_step=1e-6)


def long_command(t_end=LONG_S):
    t = np.linspace(0.0, t_end, 2001)
    return t, 0.3 * np.sin(2 * np.pi * 2 * t)


def os_threads():
    """Threads of this process (Linux: /proc/self/task)."""
    return len(os.listdir("/proc/self/task"))


def settle(baseline, within=2.0):
    """Waits until the process is back to `baseline` threads (a thread pool
    dropped ends its threads asynchronously); returns the count. A thread of
    an earlier test may end meanwhile too, so a count below `baseline` is no
    leak: callers assert `<= baseline`."""
    end = time.monotonic() + within
    while os_threads() > baseline and time.monotonic() < end:
        time.sleep(0.02)
    return os_threads()


def checkpoint():
    """Python handles a pending signal when a Python function starts."""


def kill():
    os.kill(os.getpid(), signal.SIGINT)


def interrupted_after(call, how, delay=0.5):
    """Runs `call` with a SIGINT `delay` s after the start; returns the
    seconds from the signal to the KeyboardInterrupt."""
    sent = []

    def fire():
        sent.append(time.monotonic())
        how()

    timer = threading.Timer(delay, fire)
    raised, other = None, None
    timer.start()
    try:
        call()
        # a signal the call did not raise is raised here, once it returns
        # (as before the runs polled for signals): at the next check for
        # pending signals, a Python function's start
        checkpoint()
    except KeyboardInterrupt:
        raised = time.monotonic()
    except Exception as e:  # noqa: BLE001 - reported below
        other = e
        try:
            checkpoint()
        except KeyboardInterrupt:
            raised = time.monotonic()
    finally:
        timer.cancel()
        timer.join()
    assert sent, f"the run ended before the signal ({other!r})"
    assert raised is not None, f"no KeyboardInterrupt ({other!r})"
    assert other is None, other
    return raised - sent[0]


@pytest.fixture(autouse=True)
def default_sigint():
    """The tests need Python's default SIGINT handler (KeyboardInterrupt)."""
    old = signal.signal(signal.SIGINT, signal.default_int_handler)
    yield
    signal.signal(signal.SIGINT, old)


@pytest.mark.parametrize("how", [_thread.interrupt_main, kill], ids=["interrupt_main", "os.kill"])
def test_ctrl_c_stops_a_simulate(how):
    rig = hydrocyl.Rig.load("leaney-moog")
    t, u = long_command()
    baseline = os_threads()
    took = interrupted_after(lambda: rig.simulate(t, u, **LONG), how)
    assert took < 2.0, took
    assert settle(baseline) <= baseline, "a thread outlived the interrupted run"
    # the next run is not stopped: the interrupt belonged to the one before
    short = rig.simulate(t[:11], u[:11])
    assert short["position"].shape == (11,)


@pytest.mark.parametrize("threads", [None, 2])
def test_ctrl_c_stops_every_run_of_a_batch(threads):
    rig = hydrocyl.Rig.load("leaney-moog")
    t, u = long_command()
    params = {"load.mass": np.linspace(80.0, 120.0, 6)}
    # rayon's global pool lives on once started: start it before counting
    hydrocyl.simulate_batch(rig, t[:11], u[:11], params)
    baseline = os_threads()
    took = interrupted_after(
        lambda: hydrocyl.simulate_batch(rig, t, u, params, threads=threads, **LONG), kill
    )
    assert took < 2.0, took
    assert settle(baseline) <= baseline, "a thread outlived the interrupted run"
    # the pool is idle again: a short batch runs at once
    start = time.monotonic()
    batch = hydrocyl.simulate_batch(rig, t[:11], u[:11], params, threads=threads)
    assert batch.ok.all() and time.monotonic() - start < 5.0


def test_a_run_in_another_python_thread_is_not_stopped_by_the_main_threads_signal():
    """Python handles signals in the main thread only: a run in another
    thread goes on (and the main thread gets the KeyboardInterrupt)."""
    rig = hydrocyl.Rig.load("leaney-moog")
    t, u = long_command(0.3)
    out = []
    worker = threading.Thread(target=lambda: out.append(rig.simulate(t, u, **LONG)))
    worker.start()
    try:
        with pytest.raises(KeyboardInterrupt):
            _thread.interrupt_main()
            time.sleep(5)
    finally:
        worker.join()
    assert out and out[0]["position"].shape == t.shape
