"""Helpers shared by the Python tests."""

import threading


def results_from_threads(f, n=4):
    """f() run on n threads at once; the list of what each returned."""
    results = [None] * n

    def work(i):
        results[i] = f()

    threads = [threading.Thread(target=work, args=(i,)) for i in range(n)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    return results


def main_thread_turns_during(f):
    """Runs f() on another thread and counts how often this thread ran meanwhile (each turn waits
    0.5 ms, giving the GIL away): a call that holds the GIL throughout leaves it near 0.
    Returns (what f returned, turns)."""
    started = threading.Event()
    done = []

    def work():
        started.set()
        done.append(f())

    t = threading.Thread(target=work)
    t.start()
    started.wait()
    turns = 0
    while t.is_alive() and turns < 1000:
        turns += 1
        threading.Event().wait(0.0005)  # yields the GIL, runs again when it gets it back
    t.join()
    assert done, "the call raised"
    return done[0], turns
