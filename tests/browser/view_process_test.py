#!/usr/bin/python3
"""`halfback view` as a process: a stop signal ends it within 5 s whatever it is doing.

Starts the server on a free port, starts what once kept it running after the signal (a fit of
four He lobes at the largest size, minutes long; a client that stops reading a large response; a
client trickling its request head), sends SIGTERM (then, in a second run, SIGINT) and checks that
the process exits with status 0 within 5 s. No browser is needed.

Usage: view_process_test.py --halfback PATH
"""
import argparse
import re
import signal
import socket
import subprocess
import sys
import threading
import time
import urllib.request

FAILURES = []


def check(condition, message):
    print(f"{'ok' if condition else 'FAIL'}: {message}")
    if not condition:
        FAILURES.append(message)


def start_server(halfback):
    proc = subprocess.Popen([halfback, "view", "lambert", "--port", "0", "--threads", "1"],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                            preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL))
    line = proc.stdout.readline()
    match = re.search(r"http://([^:/]+):(\d+)/\?token=([0-9a-f]+)", line)
    if not match:
        proc.kill()
        sys.exit(f"no URL in the server's first line: {line!r}")
    return proc, int(match.group(2)), match.group(3)


def get_in_background(url):
    def run():
        try:
            with urllib.request.urlopen(url, timeout=600) as r:
                r.read()
        except Exception:  # pylint: disable=broad-except
            pass  # the server stops: the connection ends
    threading.Thread(target=run, daemon=True).start()


def raw_request(port, target):
    s = socket.create_connection(("127.0.0.1", port))
    s.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, 4096)
    s.sendall(f"GET {target} HTTP/1.1\r\nHost: 127.0.0.1:{port}\r\n\r\n".encode())
    return s


def busy_server_stops(halfback, sig):
    proc, port, token = start_server(halfback)
    base = f"http://127.0.0.1:{port}"
    held = []
    try:
        get_in_background(f"{base}/api/fit?token={token}&brdf=lambert:albedo=0.3%2Bggx:alpha=0.2"
                          "&model=he%2Bhe%2Bhe%2Bhe&samples=20000")
        # A client that never reads a large answer (held by the write's deadline, 10 s).
        held.append(raw_request(port, f"/api/slices?token={token}&brdf=lambert&brdf=lambert"
                                      "&n=512&values=luminance"))
        trickler = socket.create_connection(("127.0.0.1", port))
        trickler.sendall(b"GET /api/info HTTP/1.1\r\n")
        held.append(trickler)
        time.sleep(1.5)
        check(proc.poll() is None, "the server runs its requests")
        t0 = time.monotonic()
        proc.send_signal(sig)
        try:
            code = proc.wait(timeout=5)
            seconds = time.monotonic() - t0
            check(code == 0, f"{sig.name} stops a busy server with status 0 (status {code}, "
                             f"{seconds:.2f} s)")
        except subprocess.TimeoutExpired:
            proc.kill()
            proc.wait()
            check(False, f"{sig.name} stops a busy server within 5 s")
    finally:
        for s in held:
            s.close()
        if proc.poll() is None:
            proc.kill()
            proc.wait()


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--halfback", required=True)
    args = ap.parse_args()
    for sig in (signal.SIGTERM, signal.SIGINT):
        busy_server_stops(args.halfback, sig)
    if FAILURES:
        print(f"{len(FAILURES)} failure(s)")
        sys.exit(1)
    print("all process checks passed")


if __name__ == "__main__":
    main()
