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
