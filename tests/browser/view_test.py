#!/usr/bin/python3
"""End-to-end test of `halfback view` in a real browser (headless Chromium driven by Selenium).

Starts the server on a free port, loads the page, moves the azimuth slider, drags on the
hemisphere, hovers a slice and the hemisphere, and checks that the numbers the page lists are the
ones `halfback eval` and `halfback convert` print for the same configuration. Checks that a request
without the token, with a foreign Origin, or for a path outside the roots is refused. Saves
screenshots (--screenshots DIR, view-*.png) and measures the update rate of slider moves and
hemisphere drags (printed; docs/performance.md, "Viewer"). With --measure-only it only loads the
page and measures (for timing runs of several builds one after the other, e.g. before and after a
change, on the same machine).

Usage: view_test.py --halfback PATH [--screenshots DIR] [--measure-only]
"""
import argparse
import csv
import io
import json
import math
import os
import re
import shutil
import signal
import subprocess
import sys
import tempfile
import time
import urllib.error
import urllib.request

import urllib.parse

try:
    from selenium import webdriver
    from selenium.webdriver.chrome.service import Service
    from selenium.webdriver.common.action_chains import ActionChains
    from selenium.webdriver.common.by import By
    from selenium.webdriver.support.ui import WebDriverWait
except ImportError:
    webdriver = None

SKIP = 77  # CTest's SKIP_RETURN_CODE for this test

FAILURES = []


def check(condition, message):
    if condition:
        print(f"ok: {message}")
    else:
        print(f"FAIL: {message}")
        FAILURES.append(message)


def cpu_seconds(root_pid=None):
    """User + system CPU time of a process and all its descendants (by default this script's: the
    server, chromedriver and Chromium's processes), from /proc: a cost that the load of a shared
    machine does not change, unlike the wall-clock rates."""
    root_pid = root_pid or os.getpid()
    stats = {}
    for entry in os.listdir("/proc"):
        if not entry.isdigit():
            continue
        try:
            with open(f"/proc/{entry}/stat") as f:
                fields = f.read().rsplit(")", 1)[1].split()
        except OSError:
            continue
        stats[int(entry)] = (int(fields[1]), int(fields[11]) + int(fields[12]))  # ppid, ticks
    children = {}
    for pid, (ppid, _) in stats.items():
        children.setdefault(ppid, []).append(pid)
    total, todo = 0, [root_pid]
    while todo:
        pid = todo.pop()
        total += stats.get(pid, (0, 0))[1]
        todo.extend(children.get(pid, []))
    return total / os.sysconf("SC_CLK_TCK")


SERVER = {}


def start_server(halfback, specs, root):
    proc = subprocess.Popen([halfback, "view", *specs, "--root", root, "--port", "0",
                             "--threads", "1"],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                            # a shell's background job inherits SIGINT ignored, which the server
                            # would keep: start it with the default so that Ctrl-C is tested
                            preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL))
    line = proc.stdout.readline()
    match = re.search(r"(http://[^ ]+/)\?token=([0-9a-f]+)", line)
    if not match:
        proc.kill()
        sys.exit(f"no URL in the server's first line: {line!r} {proc.stderr.read()}")
    SERVER["pid"] = proc.pid
    return proc, match.group(1), match.group(2)


def http_status(url, headers=None):
    req = urllib.request.Request(url, headers=headers or {})
    try:
        with urllib.request.urlopen(req) as r:
            return r.status, r.read()
    except urllib.error.HTTPError as e:
        return e.code, e.read()


def check_refusals(base, token):
    status, _ = http_status(f"{base}api/info")
    check(status == 403, f"a request without the token is refused ({status})")
    status, _ = http_status(f"{base}api/info?token=0123456789abcdef0123456789abcdef")
    check(status == 403, f"a request with a wrong token is refused ({status})")
    status, _ = http_status(f"{base}api/info?token={token}", {"Origin": "http://evil.example"})
    check(status == 403, f"a request with a foreign Origin is refused ({status})")
    host = base.split("/")[2]
    status, _ = http_status(f"{base}api/info?token={token}", {"Host": f"evil.example:{host.split(':')[1]}"})
    check(status == 403, f"a request with a foreign Host (DNS rebinding) is refused ({status})")
    for path in ["../../etc/passwd", "/etc/passwd", "link-out/passwd"]:
        q = urllib.parse.urlencode({"brdf": f"file:{path}", "token": token})
        status, body = http_status(f"{base}api/brdf?{q}")
        check(status == 403, f"file:{path} outside the roots is refused ({status} {body[:80]!r})")
    # A parameterization's BRDF is confined as any BRDF (no file outside the roots is opened).
    for endpoint, key, extra in [("slices", "forms", {"brdf": "lambert", "n": "4"}),
                                 ("hemisphere", "colour", {"n": "4"}),
                                 ("point", "form", {"iso": "1", "coords": "0.1,0.2,0.3"})]:
        for spec in ["dupuy-jakob:/etc/passwd", "dupuy-jakob:../../etc/passwd",
                     "dupuy-jakob:file:link-out/passwd"]:
            q = urllib.parse.urlencode({key: spec, "token": token, **extra})
            status, body = http_status(f"{base}api/{endpoint}?{q}")
            check(status == 403, f"{endpoint} {key}={spec} is refused ({status} {body[:80]!r})")
    status, _ = http_status(f"{base}api/info?token={token}")
    check(status == 200, "the server still answers after the refusals")


def run_cli(halfback, args, stdin):
    out = subprocess.run([halfback, *args], input=stdin, capture_output=True, text=True, check=True)
    return list(csv.DictReader(io.StringIO(out.stdout)))


def page_numbers(driver):
    """The numbers of the configuration table, by cell id."""
    cells = driver.find_elements(By.CSS_SELECTOR, "#cursor td")
    out = {}
    for c in cells:
        text = c.text.replace("J ", "")
        out[c.get_attribute("id")] = None if text == "—" else float(text)
    return out


def close(a, b, rel=2e-8):
    return abs(a - b) <= rel * max(1.0, abs(a), abs(b))


def check_against_cli(driver, halfback, spec, label):
    """The listed ρ and coordinates against `halfback eval` and `halfback convert`."""
    n = page_numbers(driver)
    d = [n[f"cur-dirs-{k}"] for k in ["wi_x", "wi_y", "wi_z", "wo_x", "wo_y", "wo_z"]]
    # The page shows 9 significant digits: the CLI gets the server's exact pair from the API.
    exact = driver.execute_script("return window.halfback.cursor();")
    pair = exact["wi"] + exact["wo"]
    check(all(close(a, b, 1e-8) for a, b in zip(d, pair)), f"{label}: directions shown = the API's")
    line = "wi_x,wi_y,wi_z,wo_x,wo_y,wo_z\n" + ",".join(repr(x) for x in pair) + "\n"
    rho = run_cli(halfback, ["eval", "--brdf", spec], line)[0]
    shown = [n[f"cur-rho-0-{c}"] for c in "rgb"]
    check(all(close(float(rho[c]), s) for c, s in zip("rgb", shown)),
          f"{label}: ρ shown {shown} = halfback eval {[rho[c] for c in 'rgb']}")
    for space in ["halfdiff", "ortho", "hybrid", "spherical"]:
        for iso in [False, True]:
            args = ["convert", "--from", "dirs", "--to", space, "--jacobian"] + (["--isotropic"] if iso else [])
            row = run_cli(halfback, args, line)[0]
            key = f"{space}-iso" if iso else space
            ok = all(close(float(v), n[f"cur-{key}-{k}"], 2e-8) or (abs(float(v)) < 1e-9 and abs(n[f"cur-{key}-{k}"]) < 1e-8)
                     for k, v in row.items() if k not in ("valid",))
            check(ok, f"{label}: {key} coordinates and Jacobian shown = halfback convert {row}")


def wait_idle(driver):
    driver.execute_async_script("const done = arguments[0]; window.halfback.idle().then(done);")


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--halfback", required=True)
    ap.add_argument("--screenshots", default=".")
    ap.add_argument("--measure-only", action="store_true")
    ap.add_argument("--given-only", action="store_true",
                    help="only the checks with three BRDFs given on the command line (shorter)")
    args = ap.parse_args()
    missing = [p for p in ["/usr/bin/chromium", "/usr/bin/chromedriver"] if not os.path.exists(p)]
    if webdriver is None:
        missing.append("python3-selenium")
    if missing:
        print(f"missing {', '.join(missing)} (Debian: chromium chromium-driver python3-selenium)")
        sys.exit(1 if os.environ.get("CI") == "true" else SKIP)
    os.makedirs(args.screenshots, exist_ok=True)
    if not args.measure_only:
        given_brdfs_checks(args.halfback, args.screenshots)
    if not args.given_only:
        with tempfile.TemporaryDirectory() as root:
            os.symlink("/etc", os.path.join(root, "link-out"))
            spec = "ggx:alpha=0.3,f0=0.9"
            specs = [spec, "embedded:pink-felt"]
            if args.measure_only:  # the three BRDFs of the given-BRDF checks
                specs = [os.path.join(REPO, "data", "rgl", "ilm_l3_37_metallic_rgb.bsdf"),
                         os.path.join(REPO, "data", "nbrdf", "gold-metallic-paint3.h5"),
                         "lambert:albedo=0.2+ggx:alpha=0.15,f0=0.9"]
            proc, base, token = start_server(args.halfback, specs, root)
            try:
                if args.measure_only:
                    measure_only(base, token)
                else:
                    check_refusals(base, token)
                    browser_checks(args, base, token, spec)
            finally:
                proc.send_signal(signal.SIGINT)  # Ctrl-C
                try:
                    code = proc.wait(timeout=10)
                    check(code == 0, f"Ctrl-C stops the server cleanly (exit {code})")
                except subprocess.TimeoutExpired:
                    proc.kill()
                    check(False, "Ctrl-C stops the server")
    if FAILURES:
        print(f"{len(FAILURES)} failure(s)")
        sys.exit(1)
    print("all browser checks passed")


def make_driver():
    options = webdriver.ChromeOptions()
    options.binary_location = "/usr/bin/chromium"
    # WebGL 2 (the 3D lobe) through SwiftShader, Chromium's software renderer.
    for a in ["--headless=new", "--no-sandbox", "--use-angle=swiftshader",
              "--enable-unsafe-swiftshader", "--window-size=1500,1250", "--disable-dev-shm-usage"]:
        options.add_argument(a)
    return webdriver.Chrome(service=Service("/usr/bin/chromedriver"), options=options)


def measure_slider(driver, steps):
    """Azimuth slider moves, each one waited for: updates per second (in the page's clock, from
    the input event to the four slices drawn), and the mean time of the requests and of drawing."""
    total = fetch = draw = 0.0
    sides = []
    cpu0, server0 = cpu_seconds(), cpu_seconds(SERVER["pid"])
    for k in range(steps):
        t = driver.execute_async_script("""
            const [value, done] = arguments;
            const t0 = performance.now();
            const s = document.getElementById('azimuth');
            s.value = value; s.dispatchEvent(new Event('input'));
            window.halfback.idle().then(() => done([performance.now() - t0,
                window.halfback.stats.sliceFetchMs, window.halfback.stats.sliceDrawMs,
                window.halfback.stats.sliceSide ?? 128]));""",
                                        (5 * k) % 360)
        total, fetch, draw = total + t[0], fetch + t[1], draw + t[2]
        sides.append(t[3])
    cpu, server = cpu_seconds() - cpu0, cpu_seconds(SERVER["pid"]) - server0
    print(f"measure: slider update {total / steps:.1f} ms mean: requests {fetch / steps:.1f} ms, "
          f"drawing {draw / steps:.1f} ms; slices {min(sides)}…{max(sides)} pixels a side "
          f"(median {sorted(sides)[len(sides) // 2]}); CPU time per update {1000 * cpu / steps:.1f} ms "
          f"(server {1000 * server / steps:.1f} ms, browser and test the rest)")
    return 1000 * steps / total


def measure_slider_continuous(driver, seconds=3.0, interval_ms=16):
    """The azimuth slider moved without waiting, as a hand drags it: an input event every 16 ms
    (60 per second) for 3 s. Returns the slices drawn per second in that time (the page's
    stats.sliceDraws, or for a page without it its completed updates) and the events sent."""
    drawn, elapsed, events = driver.execute_async_script("""
        const [seconds, interval, done] = arguments;
        const s = document.getElementById('azimuth'), stats = window.halfback.stats;
        const count = () => stats.sliceDraws ?? stats.updates;
        const c0 = count(), t0 = performance.now();
        let k = 0;
        const timer = setInterval(() => {
          s.value = (7 + 2 * k++) % 360; s.dispatchEvent(new Event('input'));
          if (performance.now() - t0 < 1000 * seconds) return;
          clearInterval(timer);
          const t1 = performance.now(), c1 = count();
          window.halfback.idle().then(() => done([c1 - c0, t1 - t0, k]));
        }, interval);""", seconds, interval_ms)
    rate = 1000 * drawn / elapsed
    print(f"measure: continuous slider: {events} input events in {elapsed / 1000:.2f} s, "
          f"{drawn} slice pictures drawn: {rate:.1f} per second")
    time.sleep(0.4)  # the full-resolution refinement after the move
    wait_idle(driver)
    return rate


def measure_drag(driver, steps):
    """Hemisphere drags (mousedown, then mousemove events dispatched in the page, each waited
    for until the hemisphere and the polar plot are drawn): updates per second in the page's
    clock. The drag itself is checked above with real mouse events; here the WebDriver round
    trips of each move (~100 ms on the loaded machine) would be measured instead of the page."""
    total = 0.0
    parts = {}  # the page's stats: each view's request (server and transfer) and drawing, ms
    driver.execute_script("""
        const c = document.getElementById('hemisphere'), r = c.getBoundingClientRect();
        c.dispatchEvent(new MouseEvent('mousedown', {clientX: r.left + r.width * 0.3,
            clientY: r.top + r.height * 0.5, bubbles: true}));""")
    cpu0, server0 = cpu_seconds(), cpu_seconds(SERVER["pid"])
    for k in range(steps):
        t, got = driver.execute_async_script("""
            const [k, done] = arguments;
            const c = document.getElementById('hemisphere'), r = c.getBoundingClientRect();
            const t0 = performance.now();
            c.dispatchEvent(new MouseEvent('mousemove', {clientX: r.left + r.width * (0.2 + 0.01 * (k % 30)),
                clientY: r.top + r.height * 0.4, bubbles: true}));
            window.halfback.idle().then(() => {
              const s = window.halfback.stats;
              done([performance.now() - t0, [s.hemiFetchMs, s.hemiDrawMs, s.polarFetchMs, s.polarDrawMs]]);
            });""", k)
        total += t
        for name, v in zip(["hemisphere request", "hemisphere drawing", "polar request", "polar drawing"], got):
            if v is not None:  # a page without these stats
                parts[name] = parts.get(name, 0.0) + v
    cpu, server = cpu_seconds() - cpu0, cpu_seconds(SERVER["pid"]) - server0
    driver.execute_script("window.dispatchEvent(new MouseEvent('mouseup'));")
    print(f"measure: hemisphere drag update {total / steps:.1f} ms mean: "
          + ", ".join(f"{name} {v / steps:.1f} ms" for name, v in parts.items())
          + f"; CPU time per update {1000 * cpu / steps:.1f} ms (server {1000 * server / steps:.1f} ms, "
          f"browser and test the rest)")
    return 1000 * steps / total


def measure_all(driver):
    """The three rates, measured with the spheres finished or stopped (their passes would compete
    for the same cores; on a loaded machine all 32 passes can take minutes)."""
    passes = driver.execute_async_script(
        "window.halfback.spheresDone(32, 120).then(arguments[0]);")
    driver.execute_async_script("window.halfback.stopSpheres().then(arguments[0]);")
    print(f"measure: the spheres stopped at {passes} of 32 passes")
    wait_idle(driver)
    fps_slider = measure_slider(driver, 40)
    fps_continuous = measure_slider_continuous(driver)
    fps_drag = measure_drag(driver, 40)
    load = os.getloadavg()[0]
    print(f"measure: azimuth slider {fps_slider:.1f} updates/s (each waited for), "
          f"{fps_continuous:.1f} pictures/s (moved continuously), hemisphere drag "
          f"{fps_drag:.1f} updates/s (load average {load:.1f} on {os.cpu_count()} cores)")
    check(fps_slider > 0 and fps_drag > 0, "updates measured")


# The benchmark's browser: Chromium as a user starts it, without a GL flag. On a machine without
# a GPU it then runs WebGL 2 (the lobe) on ANGLE over SwiftShader, as --use-angle=swiftshader
# does; --use-gl=swiftshader has no WebGL 2 at all (no lobe drawn: a faster page that is not the
# user's). The renderer it uses is printed with the rates.
MEASURE_FLAGS = ["--headless=new", "--no-sandbox", "--disable-dev-shm-usage"]


def make_measure_driver():
    options = webdriver.ChromeOptions()
    options.binary_location = "/usr/bin/chromium"
    for a in MEASURE_FLAGS:
        options.add_argument(a)
    return webdriver.Chrome(service=Service("/usr/bin/chromedriver"), options=options)


def measure_only(base, token):
    """The rates with three BRDFs (a measured file, a neural BRDF, a sum of models) and every
    view on screen (the window as tall as the page)."""
    driver = make_measure_driver()
    driver.set_script_timeout(600)
    try:
        driver.set_window_size(1600, 1250)
        driver.get(f"{base}?token={token}")
        WebDriverWait(driver, 120).until(lambda d: d.find_element(By.ID, "status").text.startswith("ready"))
        for k in range(3):
            driver.execute_async_script("Promise.resolve(window.halfback.addBrdf(arguments[0])).then(arguments[1]);", f"arg:{k}")
        wait_idle(driver)
        height = driver.execute_script("return document.documentElement.scrollHeight;")
        driver.set_window_size(1600, height + 140)
        time.sleep(0.5)
        wait_idle(driver)
        renderer = driver.execute_script("""const g = document.createElement('canvas').getContext('webgl2');
            if (!g) return 'no WebGL 2';
            const e = g.getExtension('WEBGL_debug_renderer_info');
            return e ? g.getParameter(e.UNMASKED_RENDERER_WEBGL) : g.getParameter(g.RENDERER);""")
        shown = driver.execute_script("return window.halfback.state.a ? 1 + (window.halfback.state.b ? 1 : 0) + window.halfback.state.more.length : 0;")
        print(f"measure: Chromium {driver.capabilities.get('browserVersion')} with {' '.join(MEASURE_FLAGS)} "
              f"(no GL flag): WebGL 2 on {renderer}; {shown} BRDFs shown, window 1600 x {height + 140}")
        measure_all(driver)
    finally:
        driver.quit()


def slider_values(driver, names):
    """Each model slider's position, shown number and the parameter it follows ('' if none)."""
    return driver.execute_script("""
        return arguments[0].map((n) => {
          const s = document.querySelector(`#sliders input[data-param="${n}"]`);
          return [s.value, s.parentElement.querySelector('output').textContent,
                  s.dataset.follows || ''];
        });""", names)


def move_model_slider(driver, name, position):
    driver.execute_script("""const s = document.querySelector(`#sliders input[data-param="${arguments[0]}"]`);
        s.value = arguments[1]; s.dispatchEvent(new Event('input'));""", name, position)
    wait_idle(driver)


def check_following_sliders(driver):
    """alpha_x and alpha_y default to alpha: their sliders move with it until moved themselves."""
    (a, ax, ay) = slider_values(driver, ["alpha", "alpha_x", "alpha_y"])
    check(ax == [a[0], a[1], "alpha"] and ay == [a[0], a[1], "alpha"],
          f"alpha_x and alpha_y show alpha's value while they follow it ({a} {ax} {ay})")
    move_model_slider(driver, "alpha_x", "700")
    move_model_slider(driver, "alpha", "250")
    (a, ax, ay) = slider_values(driver, ["alpha", "alpha_x", "alpha_y"])
    check(ay == [a[0], a[1], "alpha"] and a[0] == "250",
          f"alpha_y still follows alpha ({a} {ay})")
    check(ax[0] == "700" and ax[2] == "" and ax[1] != a[1],
          f"alpha_x, once moved, keeps its own value ({ax})")
    spec_now = driver.execute_script("return window.halfback.state.a;")
    check("alpha_x=" in spec_now and "alpha_y=" not in spec_now,
          f"the spec names the moved parameter only ({spec_now})")


def select_brdf(driver, value):
    driver.execute_script("""const s = document.getElementById('brdf-a');
        if (![...s.options].some((o) => o.value === arguments[0])) s.append(new Option(arguments[0], arguments[0]));
        s.value = arguments[0]; s.dispatchEvent(new Event('change'));""", value)
    wait_idle(driver)


def check_sliders_follow_the_brdf(driver):
    """A model's sliders leave with it (the old page kept Beckmann's on screen
    over a measured BRDF, and moving one replaced that BRDF)."""
    select_brdf(driver, "beckmann")
    check(driver.find_element(By.ID, "model").is_displayed()
          and driver.find_elements(By.CSS_SELECTOR, '#sliders input[data-param="alpha"]'),
          "a model shows its sliders")
    select_brdf(driver, "embedded:pink-felt")
    shown = driver.find_element(By.ID, "model").is_displayed()
    left = len(driver.find_elements(By.CSS_SELECTOR, "#sliders input, #sliders select"))
    check(not shown and left == 0,
          f"a measured BRDF shows no model sliders (panel shown: {shown}, {left} controls left)")


def check_sum_of_models(driver):
    """A sum of models, typed in the load box, gets sliders for each term at
    their values, and moving one keeps the other terms."""
    box = driver.find_element(By.ID, "load-spec")
    box.clear()
    box.send_keys("lambert:albedo=0.3+ggx:alpha=0.1")
    box.submit()
    WebDriverWait(driver, 30).until(
        lambda d: d.find_element(By.ID, "status").text.startswith(("loaded", "'")) or
        "error" in d.find_element(By.ID, "status").get_attribute("class"))
    wait_idle(driver)
    status = driver.find_element(By.ID, "status").text
    check(status.startswith("loaded"), f"the load box accepts a sum ({status!r})")
    (albedo, alpha) = slider_values(driver, ["albedo", "alpha"])
    check(albedo[1] == "0.300" and alpha[1] == "0.100",
          f"each term's sliders show its values (albedo {albedo[1]}, alpha {alpha[1]})")
    move_model_slider(driver, "albedo", "600")
    spec_now = driver.execute_script("return window.halfback.state.a;")
    check(spec_now.startswith("lambert:albedo=0.6") and spec_now.endswith("+ggx:alpha=0.1"),
          f"moving a term's slider keeps the other term ({spec_now})")
    status = driver.find_element(By.ID, "status")
    check("error" not in status.get_attribute("class"), f"the sum evaluates ({status.text!r})")


def check_hemisphere_drag(driver):
    """During a drag the hemisphere keeps its size on screen (the old canvas
    shrank from 256 to 128 px at the drag's resolution, and the pointer fell off it)."""
    hemi = driver.find_element(By.ID, "hemisphere")
    # Wholly in view: a pointer's origin at an element is the centre of its visible part.
    driver.execute_script("arguments[0].scrollIntoView({block: 'center'});", hemi)
    w = hemi.size["width"]
    chain = ActionChains(driver).move_to_element_with_offset(hemi, 0, 0).click_and_hold()
    thetas, sizes = [], []
    for _ in range(4):
        chain.move_by_offset(w // 10, 0).perform()
        chain = ActionChains(driver)
        wait_idle(driver)
        thetas.append(driver.execute_script("return window.halfback.state.to;"))
        sizes.append(driver.execute_script(
            "const c = document.getElementById('hemisphere'); return [c.width, c.getBoundingClientRect().width];"))
    ActionChains(driver).release().perform()
    wait_idle(driver)
    check(all(abs(s[1] - w) < 1 for s in sizes),
          f"the hemisphere keeps its size on screen while dragged (canvas, CSS px: {sizes})")
    check(all(b > a + 1 for a, b in zip(thetas, thetas[1:])),
          f"θo follows the pointer outwards through the drag ({[round(t, 1) for t in thetas]})")


def check_roughness_slider(driver):
    """A roughness slider over [0.001, 10] is logarithmic (α = 0.2 sat at 2 % of
    the old linear track, in steps of 0.01)."""
    select_brdf(driver, "ggx:alpha=0.2")
    (alpha,) = slider_values(driver, ["alpha"])
    position = int(alpha[0])
    check(300 <= position <= 800, f"α = 0.2 sits in the middle of the track ({position} / 1000)")
    move_model_slider(driver, "alpha", str(position + 1))
    (step,) = slider_values(driver, ["alpha"])
    check(0 < float(step[1]) / float(alpha[1]) - 1 < 0.02,
          f"one step moves α by less than 2 % ({alpha[1]} → {step[1]})")


def type_into(driver, element_id, text):
    from selenium.webdriver.common.keys import Keys
    field = driver.find_element(By.ID, element_id)
    field.send_keys(Keys.CONTROL, "a")
    field.send_keys(text, Keys.ENTER)
    wait_idle(driver)


def check_typed_angles(driver):
    """θo, φo and the relative azimuth typed in as numbers; a wrong one is refused with
    a message and leaves the state as it was."""
    type_into(driver, "theta-o", "30")
    type_into(driver, "phi-o", "90")
    type_into(driver, "azimuth-value", "45")
    got = driver.execute_script("const s = window.halfback.state; return [s.to, s.po, s.az];")
    check(got == [30, 90, 45], f"typed θo, φo and relative azimuth set the state ({got})")
    check("to=30&po=90" in driver.current_url, "the typed ωo is in the URL")
    type_into(driver, "theta-o", "95")
    status = driver.find_element(By.ID, "status")
    got = driver.execute_script("return window.halfback.state.to;")
    check(got == 30 and "θo must be" in status.text,
          f"θo = 95° is refused ({status.text!r}; θo stays {got})")


def check_anisotropic_orientation(driver):
    """An anisotropic BRDF's slices at a chosen orientation, said on the page; no such
    control for isotropic ones."""
    select_brdf(driver, "ggx:alpha=0.2")
    check(not driver.find_element(By.ID, "pose-box").is_displayed(),
          "an isotropic BRDF has no orientation control")
    select_brdf(driver, "ggx:alpha_x=0.1,alpha_y=0.4")
    check(driver.find_element(By.ID, "pose-box").is_displayed(),
          "an anisotropic BRDF has the orientation control")
    before = driver.execute_script("return window.halfback.stats.sliceDraws;")
    type_into(driver, "pose-value", "90")
    note = driver.find_element(By.ID, "pose-note").text
    after = driver.execute_script("return window.halfback.stats.sliceDraws;")
    check("anisotropic" in note and "90°" in note and after > before,
          f"the slices are redrawn at the orientation typed, and the page says it ({note!r})")
    check("pose=90" in driver.current_url, "the orientation is in the URL")
    type_into(driver, "pose-value", "0")


def check_lobe(driver, token):
    """The 3D lobe draws every BRDF loaded, and its radii are the server's ρ (a vertex's
    value read back from the page against /api/point at its direction)."""
    time.sleep(0.4)  # the views that follow at rest (the lobe) after the last move
    wait_idle(driver)
    got = driver.execute_async_script("""
        const done = arguments[arguments.length - 1], token = arguments[0];
        const meshes = window.halfback.lobe();
        if (!meshes.length) return done({ error: 'no lobe drawn' });
        const s = window.halfback.state, D = Math.PI / 180;
        const wo = [Math.sin(s.to * D) * Math.cos(s.po * D), Math.sin(s.to * D) * Math.sin(s.po * D), Math.cos(s.to * D)];
        const checks = [];
        for (const [b, m] of meshes.entries()) {
          let best = -1;
          for (let k = 0; k < m.values.length; ++k) if (m.values[k] > (best < 0 ? -1 : m.values[best])) best = k;
          for (const k of [best, (m.n * m.n) >> 1, (m.n * (m.n + 1)) >> 2]) {
            if (!Number.isFinite(m.values[k])) continue;
            const wi = Array.from(m.dirs.slice(3 * k, 3 * k + 3));
            checks.push({ b, wi, value: m.values[k], brdf: [s.a, s.b, ...s.more].filter(Boolean)[b] });
          }
        }
        // Pixels that are not the background: the lobe was drawn.
        const c = document.getElementById('lobe'), copy = document.createElement('canvas');
        copy.width = c.width; copy.height = c.height;
        copy.getContext('2d').drawImage(c, 0, 0);
        const px = copy.getContext('2d').getImageData(0, 0, c.width, c.height).data;
        let drawn = 0;
        for (let k = 0; k < px.length; k += 4) drawn += Math.abs(px[k] - 17) + Math.abs(px[k + 2] - 23) > 30;
        Promise.all(checks.map((q) => fetch(`/api/point?wi=${q.wi.join(',')}&wo=${wo.join(',')}&brdf=${encodeURIComponent(q.brdf)}&token=${token}`)
          .then((r) => r.json()).then((j) => { const r = j.rho[0].rgb; q.server = 0.2126 * r[0] + 0.7152 * r[1] + 0.0722 * r[2]; }))
        ).then(() => done({ checks, drawn, brdfs: meshes.length, pixels: px.length / 4 }),
               (e) => done({ error: String(e) }));
    """, token)
    check("error" not in got, f"the page drew a lobe ({got.get('error', '')})")
    if "error" in got:
        return
    ok = all(abs(q["value"] - q["server"]) <= 2e-5 * max(1e-3, abs(q["server"])) for q in got["checks"])
    check(ok and len(got["checks"]) >= 4,
          f"the lobe's radii are the server's ρ ({[(round(q['value'], 6), round(q['server'], 6)) for q in got['checks']]})")
    check(got["brdfs"] == 2 and got["drawn"] > 0.03 * got["pixels"],
          f"the lobe shows both BRDFs ({got['brdfs']}) and covers the canvas ({got['drawn']} of {got['pixels']} pixels)")


def check_albedo(driver, halfback):
    """The albedo plot shows every BRDF loaded, and its points are `halfback info`'s."""
    curves = driver.execute_script("return window.halfback.albedo();")
    specs = driver.execute_script("const s = window.halfback.state; return [s.a, s.b].filter(Boolean);")
    check(len(curves) == len(specs) == 2, f"the albedo plot has a curve per BRDF ({len(curves)})")
    legend = driver.find_element(By.ID, "albedo").text
    check(all(s in legend for s in ["ggx:alpha=0.3,f0=0.9", "embedded:pink-felt"]),
          f"the albedo plot names the BRDFs ({legend!r})")
    text = subprocess.run([halfback, "info", "--albedo-samples", "64", "ggx:alpha=0.3,f0=0.9"],
                          capture_output=True, text=True, check=True).stdout
    cli = {float(m.group(1)): [float(v) for v in m.group(2).split(", ")]
           for m in re.finditer(r"albedo at θi = ([0-9.]+)°: +([-0-9.e, ]+?)  ", text)}
    page = {t: a for t, a in zip(curves[0]["theta_deg"], curves[0]["albedo"])}
    pairs = [(page[t], cli[t]) for t in cli if t in page]
    check(len(pairs) == 4 and all(close(p, c, 1e-5) for pp, cc in pairs for p, c in zip(pp, cc)),
          f"the albedo curve's points are halfback info's ({pairs})")


def check_three_brdfs(driver):
    """A measured file, a neural BRDF and a model at once: every plot shows the three
    with their names; removing one takes it out of every plot."""
    third = "embedded:acrylic_felt_green"
    driver.execute_async_script("window.halfback.addBrdf(arguments[0]).then(arguments[1]);", third)
    wait_idle(driver)
    driver.execute_async_script("window.halfback.spheresDone(1).then(arguments[0]);")
    names = ["ggx:alpha=0.3,f0=0.9", "embedded:pink-felt", third]
    for plot in ["polar", "albedo", "more"]:
        text = driver.find_element(By.ID, plot).text
        shown = [n for n in names if n in text]
        check(third in shown and (plot == "more" or len(shown) == 3),
              f"the {plot} legend names the BRDFs shown ({shown})")
    lobes = driver.execute_script("return window.halfback.lobe().length;")
    spheres = driver.find_elements(By.CSS_SELECTOR, "#spheres canvas[id^='sphere-']")
    lights = driver.find_elements(By.CSS_SELECTOR, "#spheres canvas[id^='pointlight-']")
    check(len(lights) == 3, f"a sphere under a point light beside each ({len(lights)})")
    check(lobes == 3 and len(spheres) == 3, f"three lobes ({lobes}) and three spheres ({len(spheres)})")
    hemi = driver.find_element(By.ID, "hemisphere")
    driver.execute_script("arguments[0].scrollIntoView({block: 'center'});", hemi)
    ActionChains(driver).move_to_element_with_offset(hemi, 20, -10).perform()  # hover: a cursor
    wait_idle(driver)
    rows = driver.find_elements(By.CSS_SELECTOR, "#cursor td[id^='cur-rho-'][id$='-r']")
    check(len(rows) == 3, f"the configuration lists ρ of the three BRDFs ({len(rows)})")
    driver.find_element(By.CSS_SELECTOR, "#more .chip button.remove").click()
    wait_idle(driver)
    text = driver.find_element(By.ID, "polar").text
    check(third not in text and driver.execute_script("return window.halfback.state.more.length;") == 0,
          "the × of a chip removes that BRDF from the plots")


def check_exports(driver, spec, screenshots):
    """Each view's export is a figure: a title naming the view and the BRDFs, the
    pictures, axes, colour bars and legends as on the page; the SVG is valid (an image of it
    loads) and the PNG is drawn from it (saved as view-export-*.png)."""
    import base64
    for target, parts in [("slices", ["<image", "relative azimuth", "luminance"]),
                          ("hemisphere", ["<image", "θo =", "θ 60°"]), ("polar", ["0°", "radius"]),
                          ("theta", ["against θi", "log"]),
                          ("lobe", ["<image"]), ("albedo", ["θi", "albedo"]),
                          ("sphere", ["<image", "samples per pixel"])]:
        got = driver.execute_async_script("""
            const done = arguments[1], svg = window.halfback.figure(arguments[0]);
            const img = new Image();
            img.onload = () => {
              const c = document.createElement('canvas');
              c.width = img.width; c.height = img.height;
              c.getContext('2d').drawImage(img, 0, 0);
              done({ svg, png: c.toDataURL('image/png') });
            };
            img.onerror = () => done({ svg, png: null });
            img.src = URL.createObjectURL(new Blob([svg], { type: 'image/svg+xml' }));""", target)
        svg = got["svg"]
        missing = [p for p in ["halfback view", spec] + parts if p not in svg]
        check(not missing and got["png"], f"the {target} export is a figure (missing: {missing}, "
              f"SVG loads: {bool(got['png'])})")
        if got["png"]:
            with open(os.path.join(screenshots, f"view-export-{target}.png"), "wb") as f:
                f.write(base64.b64decode(got["png"].split(",", 1)[1]))


def check_point_light(driver):
    """The sphere under a point light from ωo: drawn, and its light moves with ωo (the
    brightest pixel of a glossy sphere moves when φo turns by 180°)."""
    brightest = """
        const c = document.getElementById('pointlight-0'), px = c.getContext('2d').getImageData(0, 0, c.width, c.height).data;
        let best = 0;
        for (let k = 0; k < px.length; k += 4) if (px[k] + px[k + 1] > px[best] + px[best + 1]) best = k;
        return [(best / 4) % c.width, Math.floor(best / 4 / c.width), px[best]];"""
    type_into(driver, "theta-o", "40")
    type_into(driver, "phi-o", "0")
    time.sleep(0.4)
    wait_idle(driver)
    right = driver.execute_script(brightest)
    type_into(driver, "phi-o", "180")
    time.sleep(0.4)
    wait_idle(driver)
    left = driver.execute_script(brightest)
    check(right[2] > 0 and right[0] > left[0] + 20,
          f"the point light's highlight follows ωo (φo = 0°: x = {right[0]}, 180°: x = {left[0]})")


def check_fit(driver, halfback, screenshots):
    """A measured BRDF and its fit overlaid: the page's fit is `halfback fit`'s, its
    parameters are listed, it is the compare BRDF of every plot, and a fit with another model and
    loss replaces it."""
    measured = "embedded:acrylic_felt_green"  # an RGL measurement (the embedded file)
    select_brdf(driver, measured)

    def fit(model, loss):
        driver.execute_script("""document.getElementById('fit-model').value = arguments[0];
            document.getElementById('fit-loss').value = arguments[1];""", model, loss)
        before = driver.execute_script("const f = window.halfback.fit(); return f && f.spec;")
        driver.find_element(By.ID, "fit-run").click()
        WebDriverWait(driver, 120).until(lambda d: d.execute_script(
            "const f = window.halfback.fit(); return f && f.spec !== arguments[0];", before))
        time.sleep(0.3)
        wait_idle(driver)
        return driver.execute_script("return window.halfback.fit();")

    got = fit("lambert+ggx", "ngan")
    with tempfile.TemporaryDirectory() as tmp:
        out = os.path.join(tmp, "fit.json")
        printed = subprocess.run([halfback, "fit", "--brdf", measured, "--model",
                                  "lambert+ggx", "--loss", "ngan", "--samples", "5000", "-o", out],
                                 capture_output=True, text=True, check=True).stdout.strip()
        with open(out, encoding="utf-8") as f:
            cli = json.load(f)
    values = lambda r: [p["value"] for t in r["terms"] for p in t["parameters"]]
    check(all(close(a, b, 1e-6) for a, b in zip(values(got), values(cli))) and
          close(got["loss"]["value"], cli["loss"]["value"], 1e-6),
          f"the page's fit is halfback fit's ({got['spec']} vs {printed})")
    state = driver.execute_script("return window.halfback.state;")
    check(state["b"] == got["spec"] and state["mode"] == "diff",
          f"the fit is the compare BRDF, shown as the difference ({state['b'][:40]}, {state['mode']})")
    table = driver.find_element(By.ID, "fit-result").text
    names = [p["name"] for t in got["terms"] for p in t["parameters"]]
    check(all(n in table for n in names) and "ngan loss" in table and f"{got['starts']} starts" in table,
          f"the fit's parameters, loss and starts are listed ({names})")
    shown = [f"{float(v):.6g}" for v in re.findall(r"^\S+ \S+ ([-0-9.e]+)", table, re.M)]
    check(shown == [f"{v:.6g}" for v in values(got)], f"the listed values are the fit's ({shown})")
    for plot in ["polar", "albedo"]:
        legend = driver.find_element(By.ID, plot).text
        check(f"fit of {measured}: lambert+ggx (ngan)" in legend,
              f"the {plot} plot overlays the fit with its name ({legend[-80:]!r})")
    panel = driver.find_element(By.ID, "fit-panel")
    driver.execute_script("arguments[0].scrollIntoView({block: 'start'});", panel)
    panel.screenshot(os.path.join(screenshots, "view-fit.png"))
    driver.find_element(By.ID, "polar-panel").screenshot(os.path.join(screenshots, "view-fit-polar.png"))
    slices = driver.find_element(By.ID, "slices-panel")
    driver.execute_script("arguments[0].scrollIntoView({block: 'start'});", slices)
    slices.screenshot(os.path.join(screenshots, "view-fit-difference.png"))

    again = fit("ggx", "low-e2")
    table = driver.find_element(By.ID, "fit-result").text
    check(again["loss"]["name"] == "low-e2" and again["model"] == "ggx" and "albedo_r" not in table
          and "low-e2 loss" in table and driver.execute_script("return window.halfback.state.b;") == again["spec"],
          f"a fit with another model and loss replaces the first ({again['spec'][:60]})")
    select_brdf(driver, "arg:0")
    driver.execute_script("""const s = document.getElementById('brdf-b');
        s.value = 'arg:1'; s.dispatchEvent(new Event('change'));""")
    wait_idle(driver)


def browser_checks(args, base, token, spec):
    driver = make_driver()
    driver.set_script_timeout(300)
    try:
        driver.get(f"{base}?token={token}")
        WebDriverWait(driver, 60).until(
            lambda d: d.find_element(By.ID, "status").text == "ready")
        wait_idle(driver)
        check(driver.find_element(By.ID, "slice-halfdiff").size["width"] > 0, "the page shows the slices")
        # The azimuth slider.
        slider = driver.find_element(By.ID, "azimuth")
        ActionChains(driver).click_and_hold(slider).move_by_offset(30, 0).release().perform()
        wait_idle(driver)
        time.sleep(0.4)  # the full-resolution refinement after the move
        wait_idle(driver)
        az = float(slider.get_attribute("value"))
        check(az > 0, f"moving the slider sets the azimuth ({az}°)")
        check(f"az={az:g}" in driver.current_url, "the azimuth is in the page's URL")
        # Drag on the hemisphere: ωo moves.
        hemi = driver.find_element(By.ID, "hemisphere")
        driver.execute_script("arguments[0].scrollIntoView({block: 'center'});", hemi)
        before = driver.execute_script("return [window.halfback.state.to, window.halfback.state.po];")
        w = hemi.size["width"]
        driver.execute_script("performance.setResourceTimingBufferSize(10000); performance.clearResourceTimings();")
        ActionChains(driver).move_to_element_with_offset(hemi, -w // 3, w // 6).click_and_hold() \
            .move_by_offset(w // 10, 0).move_by_offset(w // 10, 0).release().perform()
        wait_idle(driver)
        after = driver.execute_script("return [window.halfback.state.to, window.halfback.state.po];")
        check(after != before, f"dragging on the hemisphere moves ωo ({before} → {after})")
        time.sleep(0.4)
        wait_idle(driver)
        # At rest the views a drag drew coarse are drawn again at their resolution (the hemisphere
        # at its side in device pixels, the polar curves at 181 angles), and the slices, which do
        # not depend on ωo, are not asked again (they were, a second of server time with three
        # BRDFs).
        sizes = driver.execute_script("""const n = (p) => performance.getEntriesByType('resource')
              .map((e) => new URL(e.name)).filter((u) => u.pathname === p).map((u) => Number(u.searchParams.get('n')));
            const c = document.getElementById('hemisphere');
            return [n('/api/hemisphere'), n('/api/polar'), n('/api/slices').length, c.width,
                    Math.min(512, Math.round(c.getBoundingClientRect().width * (window.devicePixelRatio || 1)))];""")
        hemi_n, polar_n, slices, canvas_w, side = sizes
        hemi_n = [n for n in hemi_n if n != 96]  # the lobe's requests (96 × 96) left out
        check(128 in hemi_n and hemi_n[-1] == side == canvas_w and 91 in polar_n and polar_n[-1] == 181 and slices == 0,
              f"a drag of ωo: coarse while it moves, refined at rest, the slices not asked again "
              f"(hemisphere n {hemi_n}, canvas {canvas_w} of {side}; polar n {polar_n}; slices requests {slices})")
        # Hover a slice: the listed numbers against the CLI.
        sl = driver.find_element(By.ID, "slice-halfdiff")
        driver.execute_script("arguments[0].scrollIntoView({block: 'center'});", sl)
        ActionChains(driver).move_to_element_with_offset(sl, -40, 30).perform()
        wait_idle(driver)
        check(driver.execute_script("return window.halfback.cursor() && window.halfback.cursor().valid;"),
              "hovering a slice sets a valid configuration")
        check_against_cli(driver, args.halfback, spec, "slice hover")
        # Hover the hemisphere (the pair the page computed from the pointer).
        driver.execute_script("arguments[0].scrollIntoView({block: 'center'});", hemi)
        ActionChains(driver).move_to_element_with_offset(hemi, w // 5, -w // 7).perform()
        wait_idle(driver)
        check_against_cli(driver, args.halfback, spec, "hemisphere hover")
        passes = driver.execute_async_script(
            "window.halfback.spheresDone(32, 120).then(arguments[0]);")
        print(f"note: the page's screenshot shows the spheres at {passes} of 32 passes")
        wait_idle(driver)
        driver.execute_script("window.scrollTo(0, 0);")
        driver.save_screenshot(os.path.join(args.screenshots, "view-page.png"))
        for id_, name in [("slices-panel", "slices"), ("hemisphere-panel", "hemisphere"),
                          ("polar-panel", "polar"), ("sphere-panel", "sphere"), ("cursor-panel", "cursor")]:
            panel = driver.find_element(By.ID, id_)
            driver.execute_script("arguments[0].scrollIntoView({block: 'start'});", panel)
            panel.screenshot(os.path.join(args.screenshots, f"view-{name}.png"))
        # A model's slider: the spec follows, the views update.
        alpha = driver.find_element(By.CSS_SELECTOR, '#sliders input[data-param="alpha"]')
        ActionChains(driver).click_and_hold(alpha).move_by_offset(-25, 0).release().perform()
        wait_idle(driver)
        spec_now = driver.execute_script("return window.halfback.state.a;")
        check(spec_now.startswith("ggx:alpha=") and spec_now != spec,
              f"moving the alpha slider changes the BRDF ({spec_now})")
        check_following_sliders(driver)
        for bug in [check_sliders_follow_the_brdf, check_sum_of_models, check_roughness_slider,
                    check_hemisphere_drag, check_typed_angles, check_anisotropic_orientation,
                    check_point_light]:
            try:  # each one checked even when another fails (they fail apart on the old page)
                bug(driver)
            except Exception as e:  # pylint: disable=broad-except
                check(False, f"{bug.__name__}: {type(e).__name__} {str(e)[:200]}")
                ActionChains(driver).release().perform()
                wait_idle(driver)
        driver.execute_script("""const s = document.getElementById('brdf-a');
            s.value = 'arg:0'; s.dispatchEvent(new Event('change'));""")
        wait_idle(driver)
        # Two BRDFs: the difference.
        driver.execute_script("""const s = document.getElementById('brdf-b');
            s.value = 'arg:1'; s.dispatchEvent(new Event('change'));""")
        wait_idle(driver)
        panel = driver.find_element(By.ID, "slices-panel")
        driver.execute_script("arguments[0].scrollIntoView({block: 'start'});", panel)
        panel.screenshot(os.path.join(args.screenshots, "view-difference.png"))
        guarded(driver, check_colourbar_labels, driver, "ggx minus pink-felt")
        legend = driver.find_element(By.ID, "polar").text
        check(spec in legend and "embedded:pink-felt" in legend,
              f"the polar plot draws both BRDFs with their names ({legend!r})")
        check_three_brdfs(driver)
        check_exports(driver, spec, args.screenshots)
        check_lobe(driver, token)
        check_albedo(driver, args.halfback)
        check_fit(driver, args.halfback, args.screenshots)
        albedo_panel = driver.find_element(By.ID, "albedo-panel")
        driver.execute_script("arguments[0].scrollIntoView({block: 'start'});", albedo_panel)
        albedo_panel.screenshot(os.path.join(args.screenshots, "view-albedo.png"))
        lobe_panel = driver.find_element(By.ID, "lobe-panel")
        driver.execute_script("arguments[0].scrollIntoView({block: 'start'});", lobe_panel)
        lobe_panel.screenshot(os.path.join(args.screenshots, "view-lobe.png"))
        driver.find_element(By.ID, "polar-panel").screenshot(os.path.join(args.screenshots, "view-polar-two.png"))
        check("b=arg%3A1" in driver.current_url or "b=arg:1" in driver.current_url, "the second BRDF is in the URL")
        driver.execute_script("""const s = document.getElementById('mode');
            s.value = 'a'; s.dispatchEvent(new Event('change'));""")
        wait_idle(driver)
        measure_all(driver)
        # A reload from the shared URL restores the state.
        url = driver.current_url
        driver.get("about:blank")  # the same URL again would only change the fragment: no load
        driver.get(url)
        try:
            WebDriverWait(driver, 60).until(lambda d: d.find_element(By.ID, "status").text == "ready")
        except Exception:
            print(f"reload of {url}: status {driver.find_element(By.ID, 'status').text!r}, "
                  f"console {driver.get_log('browser')[:3]}")
            raise
        check(driver.find_element(By.ID, "azimuth").get_attribute("value") ==
              url.split("az=")[1].split("&")[0], "the state in the URL is restored on load")
        logs = [l for l in driver.get_log("browser") if l["level"] == "SEVERE"]
        check(not logs, f"no errors in the browser console {logs[:3]}")
    finally:
        driver.quit()


# --- Every BRDF given on the command line, and the page's layout and interaction with three ---

REPO = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
COLOURS = ['#ff9a3c', '#3cc8ff', '#9be37a', '#e879f9', '#f7d154', '#ff6b6b', '#a0a4ff', '#5eead4']

# The boxes (client pixels) of texts that overlap, among `selector`'s texts under an element.
OVERLAPS = """
    const [root, selector] = arguments;
    const boxes = [...root.querySelectorAll(selector)].filter((t) => t.textContent.trim())
      .map((t) => ({ r: t.getBoundingClientRect(), s: t.textContent }));
    const out = [];
    boxes.forEach((a, i) => boxes.slice(i + 1).forEach((b) => {
      const e = 0.5;
      if (a.r.right > b.r.left + e && b.r.right > a.r.left + e && a.r.bottom > b.r.top + e && b.r.bottom > a.r.top + e)
        out.push([a.s, b.s]);
    }));
    return [out, boxes.length];"""


def text_overlaps(driver, element, selector="text"):
    return driver.execute_script(OVERLAPS, element, selector)


def legend_names(driver, plot):
    """The names a plot's legend shows (its <text>s, not the titles shown on hover), with the
    title of each."""
    return driver.execute_script("""
        return [...document.querySelectorAll(`#${arguments[0]} g.legend`)].map((g) =>
          [g.querySelector('text').textContent, g.querySelector('title')?.textContent || '']);""", plot)


def status_after(driver, action, seconds=60):
    """The status line once an action has answered (ready, loaded, added or an error)."""
    driver.execute_script("document.getElementById('status').textContent = '…';")
    action()
    WebDriverWait(driver, seconds).until(lambda d: d.find_element(By.ID, "status").text != "…")
    wait_idle(driver)
    s = driver.find_element(By.ID, "status")
    return s.text, "error" in (s.get_attribute("class") or "")


def check_given_on_command_line(driver, given, names):
    """Every BRDF given on the command line is shown and named: the first, the second as the
    compare BRDF, the third beside them (a chip); each plot's legend names the three by their
    file names, with the whole spec on hover."""
    state = driver.execute_script("const s = window.halfback.state; return [s.a, s.b, s.more];")
    check(state == ["arg:0", "arg:1", ["arg:2"]],
          f"the three BRDFs of the command line are shown: first, compare, added ({state})")
    compare = driver.execute_script("const s = document.getElementById('brdf-b'); return s.selectedOptions[0].textContent;")
    check(compare == names[1], f"the compare menu names the second ({compare!r})")
    chips = driver.find_element(By.ID, "more").text
    check(names[2] in chips, f"the third is a chip ({chips!r})")
    for plot in ["polar", "albedo"]:
        legend = legend_names(driver, plot)
        check([n for n, _ in legend] == names and [t for _, t in legend] == given,
              f"the {plot} legend names the three by their file names, the whole spec on hover ({legend})")
    hemi = driver.find_element(By.ID, "hemisphere")
    driver.execute_script("arguments[0].scrollIntoView({block: 'center'});", hemi)
    ActionChains(driver).move_to_element_with_offset(hemi, 20, -10).perform()  # hover: a cursor
    wait_idle(driver)
    spheres = driver.find_elements(By.CSS_SELECTOR, "#spheres canvas")
    check(len(spheres) == 6, f"a sphere pair for each of the three ({len(spheres)} spheres)")
    rows = driver.execute_script("""return [...document.querySelectorAll('#cursor th span[title]')].map((s) => s.textContent);""")
    check(len(rows) == 3 and all("/" not in r for r in rows), f"the configuration table names the three ({rows})")


def save_export_png(driver, target, path):
    """A view's export as the page draws its PNG (the SVG figure drawn into a canvas)."""
    import base64
    png = driver.execute_async_script("""
        const done = arguments[1], img = new Image();
        img.onload = () => {
          const c = document.createElement('canvas');
          c.width = img.width; c.height = img.height;
          c.getContext('2d').drawImage(img, 0, 0);
          done(c.toDataURL('image/png'));
        };
        img.onerror = () => done(null);
        img.src = URL.createObjectURL(new Blob([window.halfback.figure(arguments[0])], { type: 'image/svg+xml' }));""", target)
    if png:
        with open(path, "wb") as f:
            f.write(base64.b64decode(png.split(",", 1)[1]))


def check_wraps(driver, width):
    """Nothing is wider than the window: the spheres wrap (3 BRDFs at 1600 px made the page
    1780 px wide and cut the sixth sphere)."""
    got = driver.execute_script("""
        const w = document.documentElement.clientWidth;
        const rights = [...document.querySelectorAll('#spheres canvas, .panel')].map((e) => e.getBoundingClientRect().right);
        return [w, document.documentElement.scrollWidth, Math.max(...rights)];""")
    check(got[1] <= got[0] and got[2] <= got[0],
          f"at {width} px the page fits the window (window {got[0]}, page {got[1]}, rightmost sphere or panel {got[2]:.0f})")
    overlaps = driver.execute_script("""
        const boxes = [...document.querySelectorAll('#spheres figcaption')].map((c) => {
          const r = document.createRange();
          r.selectNodeContents(c);
          return { r: r.getBoundingClientRect(), s: c.textContent };  // the text's extent, overflow included
        });
        const out = [];
        boxes.forEach((a, i) => boxes.slice(i + 1).forEach((b) => {
          if (a.r.right > b.r.left + 0.5 && b.r.right > a.r.left + 0.5 && a.r.bottom > b.r.top + 0.5 && b.r.bottom > a.r.top + 0.5)
            out.push([a.s, b.s]);
        }));
        return out;""")
    check(not overlaps, f"at {width} px the spheres' captions do not run into each other ({overlaps[:2]})")


def check_polar_labels(driver):
    """The polar plot's texts do not overlap (the legend sat on the 0° and 30° labels, "100" on
    "90°"), and the legend is below the plot (it sat on the curves)."""
    polar = driver.find_element(By.ID, "polar")
    overlaps, count = text_overlaps(driver, polar)
    check(count >= 10 and not overlaps, f"no two texts of the polar plot overlap ({overlaps[:4]})")
    below = driver.execute_script("""
        const svg = document.getElementById('polar'), m = svg.getScreenCTM();
        const base = new DOMPoint(0, 0).matrixTransform(m).y;
        return [...svg.querySelectorAll('g.legend text')].map((t) => t.getBoundingClientRect().top - base);""")
    check(below and all(y > 0 for y in below), f"the polar legend is below the plot's base line ({below})")


def check_colourbar_labels(driver, where):
    """The colour bars' tick labels do not overlap (a difference's collided near 0:
    "−0.01−0.0010 0.001")."""
    for bar in ["colorbar", "hemi-colorbar"]:
        box = driver.find_element(By.ID, bar)
        overlaps, count = text_overlaps(driver, box)
        ticks = [t.text for t in box.find_elements(By.TAG_NAME, "text")]
        check(count >= 3 and not overlaps, f"{where}: the {bar} labels do not overlap ({ticks}; {overlaps[:3]})")


def check_sphere_export(driver, width):
    """The sphere figure: each caption under its sphere, in lines within its width (they ran
    into each other on one line), the swatches in their BRDF's colour (they were grey)."""
    got = driver.execute_script("""
        const box = document.createElement('div');
        box.style.position = 'absolute'; box.style.left = '0'; box.style.top = '0';
        box.innerHTML = window.halfback.figure('sphere');
        document.body.append(box);
        const texts = [...box.querySelectorAll('svg > text, svg > g > text')].filter((t) => t.textContent.trim())
          .map((t) => ({ r: t.getBoundingClientRect(), s: t.textContent }));
        const overlaps = [];
        texts.forEach((a, i) => texts.slice(i + 1).forEach((b) => {
          if (a.r.right > b.r.left + 0.5 && b.r.right > a.r.left + 0.5 && a.r.bottom > b.r.top + 0.5 && b.r.bottom > a.r.top + 0.5)
            overlaps.push([a.s.slice(0, 40), b.s.slice(0, 40)]);
        }));
        const svgBox = box.firstElementChild.getBoundingClientRect();
        const outside = texts.filter((t) => t.r.right > svgBox.right + 1).map((t) => t.s.slice(0, 40));
        const swatches = [...box.querySelectorAll('tspan')].filter((t) => t.textContent.includes('■'))
          .map((t) => t.getAttribute('fill'));
        box.remove();
        return { overlaps, outside, swatches, count: texts.length };""")
    check(got["count"] >= 6 and not got["overlaps"] and not got["outside"],
          f"at {width} px the sphere export's captions do not overlap nor leave the figure ({got['overlaps'][:3]}, outside: {got['outside'][:3]})")
    want = [COLOURS[b] for b in range(3) for _ in range(2)]
    check(sorted(got["swatches"]) == sorted(want), f"at {width} px the sphere export's swatches have their BRDFs' colours ({got['swatches']})")


def check_hemisphere_click(driver):
    """A click on the hemisphere pins the ωi under the pointer and leaves ωo where it was (the
    mouse-down started a drag: ωo jumped to the click, and the pinned ωi was ωo)."""
    hemi = driver.find_element(By.ID, "hemisphere")
    driver.execute_script("arguments[0].scrollIntoView({block: 'center'});", hemi)
    before = driver.execute_script("return [window.halfback.state.to, window.halfback.state.po];")
    ActionChains(driver).move_to_element_with_offset(hemi, 40, -30).pause(0.2).click().perform()
    wait_idle(driver)
    after = driver.execute_script("return [window.halfback.state.to, window.halfback.state.po];")
    cursor = driver.execute_script("return window.halfback.cursor();")
    check(after == before, f"a click leaves ωo where it was ({before} → {after})")
    pinned = "pinned" in driver.find_element(By.ID, "cursor").text
    apart = cursor and max(abs(a - b) for a, b in zip(cursor["wi"], cursor["wo"])) > 0.1
    check(pinned and apart, f"the click pins the ωi under the pointer, not ωo (pinned: {pinned}, ωi {cursor and cursor['wi']})")
    ActionChains(driver).move_to_element_with_offset(hemi, 40, -30).click().perform()  # unpin
    wait_idle(driver)


def check_drag_to_rim(driver):
    """A drag that leaves the disk in one step puts ωo on the rim in that direction (it stayed
    where the last point inside the disk had put it)."""
    hemi = driver.find_element(By.ID, "hemisphere")
    driver.execute_script("arguments[0].scrollIntoView({block: 'center'});", hemi)
    w = hemi.size["width"]
    ActionChains(driver).move_to_element_with_offset(hemi, 10, 0).click_and_hold() \
        .move_by_offset(w // 2 + 40, 0).release().perform()
    wait_idle(driver)
    to, po = driver.execute_script("return [window.halfback.state.to, window.halfback.state.po];")
    check(abs(to - 89.9) < 0.05 and min(po, 360 - po) < 1,
          f"a drag out of the disk to the right puts ωo on the rim at φo = 0 (θo {to:.2f}, φo {po:.2f})")
    type_into(driver, "theta-o", "45")
    type_into(driver, "phi-o", "180")


def check_typed_text(driver):
    """Letters typed for θo are named in the message (it said "not ''")."""
    type_into(driver, "theta-o", "abc")
    status = driver.find_element(By.ID, "status").text
    check("'abc'" in status and "''" not in status, f"θo = abc is refused, naming what was typed ({status!r})")
    type_into(driver, "theta-o", "45")


def check_ior_sliders(driver):
    """ggx's eta and k: logarithmic over [0, 100] (η = 1.5 sat at 1.5 % of a linear track); a
    moved slider writes only the parameters the spec named or the user moved (any ggx slider
    wrote eta=0,k=0)."""
    select_brdf(driver, "ggx:alpha=0.2,eta=1.5")
    (eta,) = slider_values(driver, ["eta"])
    check(300 <= int(eta[0]) <= 800 and eta[1] == "1.50", f"η = 1.5 sits in the middle of the eta track ({eta[0]} / 1000, {eta[1]})")
    move_model_slider(driver, "eta", str(int(eta[0]) + 1))
    (step,) = slider_values(driver, ["eta"])
    check(0 < float(step[1]) / 1.5 - 1 < 0.02, f"one step moves η by less than 2 % ({eta[1]} → {step[1]})")
    select_brdf(driver, "ggx:alpha=0.2")
    move_model_slider(driver, "alpha", "600")
    spec = driver.execute_script("return window.halfback.state.a;")
    check(re.fullmatch(r"ggx:alpha=[0-9.]+", spec) is not None,
          f"moving alpha writes alpha alone, no parameter the user did not set ({spec})")


def check_load_box(driver, given, root):
    """The load box takes a path as on the command line: one relative to the root (sent as
    file:PATH), a BRDF of the command line as given there; an error names the file as typed,
    never the root's absolute path."""
    def load(text):
        box = driver.find_element(By.ID, "load-spec")
        box.clear()
        box.send_keys(text)
        return status_after(driver, box.submit)
    status, error = load("ilm_l3_37_metallic_rgb.bsdf")
    a = driver.execute_script("return window.halfback.state.a;")
    check(not error and status.startswith("loaded") and a == "file:ilm_l3_37_metallic_rgb.bsdf",
          f"a path relative to the root loads (sent as {a}; {status!r})")
    status, error = load(given[0])
    a = driver.execute_script("return window.halfback.state.a;")
    check(not error and a == "arg:0", f"the command line's path, as given, loads that BRDF ({a}; {status!r})")
    status, error = load("file:not-a-brdf.bsdf")
    check(error and "not-a-brdf.bsdf" in status and os.path.realpath(root) not in status and root not in status,
          f"a bad file's error names it as typed, not its absolute path ({status!r})")
    select_brdf(driver, "arg:0")


def check_show_needs_compare(driver):
    """"show: second" without a compare BRDF says so (it silently showed the first)."""
    driver.execute_script("""const s = document.getElementById('brdf-b');
        s.value = ''; s.dispatchEvent(new Event('change'));""")
    wait_idle(driver)
    status, error = status_after(driver, lambda: driver.execute_script("""const s = document.getElementById('mode');
        s.value = 'b'; s.dispatchEvent(new Event('change'));"""), 10)
    mode = driver.execute_script("return [window.halfback.state.mode, document.getElementById('mode').value];")
    check(error and "compare" in status and mode == ["a", "a"],
          f"show: second without a compare BRDF says that one is needed ({status!r}, mode {mode})")


def check_eight_brdfs(driver):
    """Eight BRDFs at once, one per colour, whatever the compare one (7 shown, no compare: "at
    most 8 BRDFs at once")."""
    shown = lambda: driver.execute_script("const s = window.halfback.state; return [s.a, s.b, ...s.more].filter(Boolean).length;")
    add = lambda spec: status_after(driver, lambda: driver.execute_async_script(
        "Promise.resolve(window.halfback.addBrdf(arguments[0])).then(arguments[1]);", spec))
    start = shown()
    for k in range(7 - start):
        add(f"lambert:albedo=0.{k + 1}")
    seven = shown()
    status, error = add("lambert:albedo=0.85")
    check(seven == 7 and not error and shown() == 8, f"an eighth BRDF joins seven ({seven} → {shown()}: {status!r})")
    status, error = add("lambert:albedo=0.95")
    check(error and "at most 8" in status and shown() == 8, f"a ninth is refused ({status!r})")
    while driver.execute_script("return window.halfback.state.more.length;") > 1:
        driver.execute_script("document.querySelectorAll('#more .chip button.remove')[1].click();")
    wait_idle(driver)


def chip(driver, spec, what):
    """An element of a BRDF's chip in the header: its 'show' box, 'solo' button, colour picker."""
    return driver.find_element(By.CSS_SELECTOR, f'#more .chip[data-spec="{spec}"] .{what}')


def shown_everywhere(driver):
    """What each view draws: the polar, θ and albedo legends' names, the lobe legend's text, the
    rows of slices, the spheres, the configuration's ρ rows."""
    wait_idle(driver)
    return {
        "polar": [n for n, _ in legend_names(driver, "polar")],
        "theta": [n for n, _ in legend_names(driver, "theta")],
        "albedo": [n for n, _ in legend_names(driver, "albedo")],
        "lobe": driver.find_element(By.ID, "lobe-legend").text,
        "slices": driver.execute_script(
            "return [...document.querySelectorAll('#slices .row-name')].map((e) => e.textContent.replace('■', '').trim());"),
        "spheres": len(driver.find_elements(By.CSS_SELECTOR, "#spheres canvas[id^='sphere-']")),
        # The lit mesh's images: each caption's swatch colour index and name.
        "mesh": driver.execute_script("""return [...document.querySelectorAll('#meshes figcaption')].map((c) =>
            [Number((c.querySelector('[class^="swatch-"]') || {className: 'swatch--1'}).className.slice(7)),
             c.textContent.replace('■', '').trim()]);"""),
    }


def check_show_hide_solo_colour(driver, names):
    """Per BRDF: show/hide (every view leaves it out), solo (it alone; again: all), a colour of
    one's choice (the plots' curves, the swatches and the URL follow); the last one shown cannot
    be hidden."""
    every = shown_everywhere(driver)
    check(every["polar"] == names and every["theta"] == names and every["albedo"] == names
          and every["slices"] == names and every["spheres"] == 3 and all(n in every["lobe"] for n in names)
          and every["mesh"] == [[k, n] for k, n in enumerate(names)],
          f"every view shows the three BRDFs at first ({every})")
    chip(driver, "arg:1", "show").click()
    hidden = shown_everywhere(driver)
    want = [names[0], names[2]]
    check(hidden["polar"] == want and hidden["theta"] == want and hidden["albedo"] == want
          and hidden["slices"] == want and hidden["spheres"] == 2 and names[1] not in hidden["lobe"]
          and hidden["mesh"] == [[0, names[0]], [2, names[2]]]  # each in its own colour
          and "hide=arg%3A1" in driver.current_url,
          f"hiding the second leaves it out of every view, and the URL says so ({hidden})")
    chip(driver, "arg:1", "show").click()
    check(shown_everywhere(driver)["polar"] == names, "ticked again, it is back")
    chip(driver, "arg:2", "solo").click()
    alone = shown_everywhere(driver)
    check(alone["polar"] == [names[2]] and alone["slices"] == [names[2]] and alone["spheres"] == 1
          and alone["albedo"] == [names[2]],
          f"solo shows that BRDF alone ({alone})")
    status, error = status_after(driver, lambda: chip(driver, "arg:2", "show").click(), 10)
    check(error and "at least" in status and shown_everywhere(driver)["polar"] == [names[2]],
          f"the last BRDF shown cannot be hidden ({status!r})")
    chip(driver, "arg:2", "solo").click()
    check(shown_everywhere(driver)["polar"] == names, "solo again shows them all")
    driver.execute_script("""const c = document.querySelector('#more .chip[data-spec="arg:0"] .colour');
        c.value = '#00ff00'; c.dispatchEvent(new Event('input'));""")
    wait_idle(driver)
    got = driver.execute_script("""
        const stroke = [...document.querySelectorAll('#polar path')].map((p) => p.getAttribute('stroke'));
        const sw = document.querySelector('#cursor .swatch-0, #slices .swatch-0');
        return [stroke.includes('#00ff00'), stroke.includes('#ff9a3c'), sw ? getComputedStyle(sw).color : null];""")
    check(got[0] and not got[1] and got[2] == "rgb(0, 255, 0)" and "colours=%2300ff00" in driver.current_url,
          f"a colour chosen for the first: its curves, its swatches and the URL follow ({got})")
    driver.execute_script("""const c = document.querySelector('#more .chip[data-spec="arg:0"] .colour');
        c.value = '#ff9a3c'; c.dispatchEvent(new Event('input'));""")
    wait_idle(driver)


def path_points(d):
    return [(float(x), float(y)) for x, y in re.findall(r"[ML]\s*(-?[\d.]+)[ ,](-?[\d.]+)", d)]


def check_theta_plot(driver, halfback, names, given):
    """The plot of ρ against θi: its legend names every BRDF; on the log axis (decades) and with
    ρ cos θi the drawn curve of the model sum is `halfback eval` at the plotted angles (ωi in
    the plane of incidence, θo = 45°, φo = 180°)."""
    legend = legend_names(driver, "theta")
    check([n for n, _ in legend] == names and [t for _, t in legend] == given,
          f"the θ plot's legend names the three, the whole spec on hover ({legend})")
    type_into(driver, "theta-o", "45")
    type_into(driver, "phi-o", "180")
    time.sleep(0.4)
    wait_idle(driver)
    spec = given[2]
    wo = [-math.sqrt(0.5), 0.0, math.sqrt(0.5)]  # θo = 45°, φo = 180° (sin 180° = 0)
    angles = [-60, -20, 10, 40, 45, 70]
    line = "wi_x,wi_y,wi_z,wo_x,wo_y,wo_z\n" + "".join(
        ",".join(repr(v) for v in [math.sin(math.radians(t)), 0.0, math.cos(math.radians(t))] + wo) + "\n" for t in angles)
    rows = run_cli(halfback, ["eval", "--brdf", spec], line)
    lum = [0.2126 * float(r["r"]) + 0.7152 * float(r["g"]) + 0.0722 * float(r["b"]) for r in rows]
    for quantity, scale in [("rho", "log"), ("cos", "log"), ("rho", "linear")]:
        driver.execute_script("""for (const [id, v] of [['theta-quantity', arguments[0]], ['theta-scale', arguments[1]]]) {
            const s = document.getElementById(id); s.value = v; s.dispatchEvent(new Event('change')); }""", quantity, scale)
        got = driver.execute_script("""
            const svg = document.getElementById('theta');
            const ticks = (cls) => [...svg.querySelectorAll('text.' + cls)].map((t) => [t.textContent, Number(t.getAttribute('x')), Number(t.getAttribute('y'))]);
            return { x: ticks('x-tick'), y: ticks('y-tick'), d: svg.querySelectorAll('path.curve-in_plane')[2].getAttribute('d') };""")
        xs = [(float(t.replace("°", "").replace("−", "-")), x) for t, x, _ in got["x"]]
        ys = [(float(t), y - 3) for t, _, y in got["y"]]
        if scale == "log":
            ys = [(math.log10(v), y) for v, y in ys]
            decades = all(abs(v - round(v)) < 1e-9 for v, _ in ys)
        else:
            decades = True
        (a0, px0), (a1, px1) = xs[0], xs[-1]
        (v0, py0), (v1, py1) = ys[0], ys[-1]
        points = path_points(got["d"])
        errors = []
        for t, want in zip(angles, lum):
            want = want * (math.cos(math.radians(t)) if quantity == "cos" else 1)
            px = px0 + (t - a0) * (px1 - px0) / (a1 - a0)
            near = min(points, key=lambda p: abs(p[0] - px))
            v = v0 + (near[1] - py0) * (v1 - v0) / (py1 - py0)
            value = 10 ** v if scale == "log" else v
            errors.append(abs(value / want - 1))
        # The curve is drawn at 1° steps (181 points over 180°; 2 decimals): the nearest point
        # is within half a degree, where the lobe of ggx (α = 0.15) changes by a few per cent.
        # Log axis: a relative error; linear: relative to the axis' top (a pixel is 0.5 % of it).
        if scale == "linear":
            errors = [e * want / (v1 - v0) for e, want in zip(errors, lum)]
        check(decades and max(errors) < 0.005,
              f"the θ plot ({quantity}, {scale} axis) draws halfback eval's ρ{' cos θi' if quantity == 'cos' else ''} "
              f"of the sum ({'ticks at decades' if decades and scale == 'log' else 'ticks' if decades else 'NOT decades'}; "
              f"errors {[f'{e:.1e}' for e in errors]})")
    driver.execute_script("""for (const [id, v] of [['theta-quantity', 'rho'], ['theta-scale', 'log']]) {
        const s = document.getElementById(id); s.value = v; s.dispatchEvent(new Event('change')); }""")


def check_polar_cosine(driver):
    """ρ cos θi in the polar plot: each in-plane radius is the server's ρ times cos θi over the
    largest such value (the radius of ρ alone is ρ over its largest value)."""
    for quantity in ["rho", "cos"]:
        driver.execute_script("""const s = document.getElementById('polar-quantity');
            s.value = arguments[0]; s.dispatchEvent(new Event('change'));""", quantity)
        got = driver.execute_script("""
            const paths = [...document.querySelectorAll('#polar path[stroke-dasharray="none"]')].map((p) => p.getAttribute('d'));
            return { paths, curves: window.halfback.polar() };""")
        lum = lambda v: 0.0 if v[0] is None else 0.2126 * v[0] + 0.7152 * v[1] + 0.0722 * v[2]
        values = []
        for c in got["curves"]:
            w = [lum(v) * (math.cos(math.radians(t)) if quantity == "cos" else 1) for t, v in zip(c["angles_deg"], c["in_plane"])]
            values.append(w)
        top = max(max(w) for w in values)
        worst = 0.0
        for b, w in enumerate(values):
            pts = path_points(got["paths"][b])
            for (x, y), v in zip(pts, w):
                worst = max(worst, abs(math.hypot(x, y) - v / top))
        check(len(got["paths"]) == 3 and worst < 1e-3,
              f"the polar plot's radius is {'ρ cos θi' if quantity == 'cos' else 'ρ'} over its largest value (worst {worst:.2e})")
    driver.execute_script("""const s = document.getElementById('polar-quantity'); s.value = 'rho'; s.dispatchEvent(new Event('change'));""")
    wait_idle(driver)


def check_hemisphere_marks(driver):
    """θ circles at 30° and 60° at the equal-area radius √2 sin(θ/2) of the disk, φ lines every
    45° labelled; hovering where the marks say θi = 60°, φi = 90° gives that ωi."""
    got = driver.execute_script("""
        const c = document.getElementById('hemisphere').getBoundingClientRect();
        const svg = document.getElementById('hemi-marks'), s = svg.getBoundingClientRect();
        const circles = [...svg.querySelectorAll('circle.theta-mark')].map((e) =>
          [Number(e.dataset.theta), s.left + Number(e.getAttribute('cx')) - (c.left + c.width / 2), s.top + Number(e.getAttribute('cy')) - (c.top + c.height / 2), Number(e.getAttribute('r'))]);
        const labels = [...svg.querySelectorAll('text.phi-label')].map((t) => t.textContent);
        const ninety = [...svg.querySelectorAll('text.phi-label')].find((t) => t.textContent === '90°').getBoundingClientRect();
        return { circles, labels, R: c.width / 2, up: ninety.top < c.top + 5 && Math.abs(ninety.left + ninety.width / 2 - (c.left + c.width / 2)) < 3 };""")
    R = got["R"]
    ok = sorted(t for t, *_ in got["circles"]) == [30, 60] and all(
        abs(dx) < 0.5 and abs(dy) < 0.5 and abs(r - R * math.sqrt(2) * math.sin(math.radians(t) / 2)) < 0.5
        for t, dx, dy, r in got["circles"])
    check(ok and got["labels"] == [f"{p}°" for p in range(0, 360, 45)] and got["up"],
          f"the hemisphere's θ circles and φ lines are where the projection puts them ({got})")
    hemi = driver.find_element(By.ID, "hemisphere")
    driver.execute_script("arguments[0].scrollIntoView({block: 'center'});", hemi)
    r60 = R * math.sqrt(2) * math.sin(math.radians(30))
    ActionChains(driver).move_to_element_with_offset(hemi, 0, -round(r60)).perform()
    wait_idle(driver)
    wi = driver.execute_script("return window.halfback.cursor().wi;")
    theta, phi = math.degrees(math.acos(wi[2])), math.degrees(math.atan2(wi[1], wi[0]))
    check(abs(theta - 60) < 1 and abs(phi - 90) < 1,
          f"at the marks' θ = 60°, φ = 90° the page's ωi is there (θi {theta:.2f}°, φi {phi:.2f}°)")


LOBE_PIXELS = """
    const c = document.getElementById('lobe'), k = document.createElement('canvas');
    k.width = c.width; k.height = c.height;
    const g = k.getContext('2d');
    g.drawImage(c, 0, 0);
    return Array.from(g.getImageData(0, 0, c.width, c.height).data);"""


def check_lobe_see_through(driver, base, token):
    """The BRDFs of a URL are shown and named; the lobe of two Lambertian BRDFs, one inside the other (radius 1 and ⅓): at the default
    opacity the inner one shows through the outer one (it was hidden by an opaque first
    surface); at opacity 1 it is hidden; the legend names both and says what radius 1 is (ρ =
    0.9/π = 0.29 sr⁻¹); zooming in makes the lobe larger."""
    specs = ["lambert:albedo=0.9", "lambert:albedo=0.3", "lambert:albedo=0.1"]
    q = urllib.parse.urlencode([("a", specs[0]), ("b", specs[1]), ("more", specs[2])])
    driver.get("about:blank")  # a new page, not a new fragment of this one
    driver.get(f"{base}?token={token}#{q}")
    WebDriverWait(driver, 60).until(lambda d: d.find_element(By.ID, "status").text.startswith("ready"))
    wait_idle(driver)
    chips = driver.execute_script("return [...document.querySelectorAll('#more .chip .name')].map((e) => e.textContent);")
    check(chips == specs and [n for n, _ in legend_names(driver, "polar")] == specs,
          f"the BRDFs the URL names are all shown and named (chips {chips})")
    chip(driver, specs[2], "show").click()  # the two of the check below
    lobe = driver.find_element(By.ID, "lobe")
    driver.execute_script("arguments[0].scrollIntoView({block: 'center'});", lobe)

    def pixels():
        wait_idle(driver)
        return driver.execute_script(LOBE_PIXELS)

    def differ(p, q):
        return sum(1 for k in range(0, len(p), 4) if max(abs(p[k + j] - q[k + j]) for j in range(3)) > 8)

    def with_and_without(opacity):
        driver.execute_script("const s = document.getElementById('lobe-opacity'); s.value = arguments[0]; s.dispatchEvent(new Event('input'));", opacity)
        both = pixels()
        chip(driver, "lambert:albedo=0.3", "show").click()
        first = pixels()
        chip(driver, "lambert:albedo=0.3", "show").click()
        wait_idle(driver)
        return both, first

    opaque = with_and_without(1)
    both, first = with_and_without(0.55)  # the default
    seen, hidden = differ(both, first), differ(*opaque)
    check(seen > 1000 and hidden < seen / 20,
          f"the inner lobe shows through the outer one ({seen} pixels change with it; opaque: {hidden})")
    legend = driver.find_element(By.ID, "lobe-legend").text
    check("lambert:albedo=0.9" in legend and "lambert:albedo=0.3" in legend and "0.29 sr⁻¹" in legend,
          f"the lobe's legend names both and its scale (0.9/π = 0.29 sr⁻¹): {legend!r}")
    background = lambda p: sum(1 for k in range(0, len(p), 4) if p[k] + p[k + 1] + p[k + 2] > 120)
    driver.execute_script("const s = document.getElementById('lobe-zoom'); s.value = 2; s.dispatchEvent(new Event('input'));")
    zoomed = pixels()
    check(background(zoomed) > 1.3 * background(both), f"zoom 2 enlarges the lobe ({background(both)} → {background(zoomed)} lit pixels)")
    driver.execute_script("const s = document.getElementById('lobe-zoom'); s.value = 1; s.dispatchEvent(new Event('input'));")


VIEW_SIZES = """
    const w = (sel) => { const e = document.querySelector(sel); return e ? e.getBoundingClientRect().width : 0; };
    return { hemisphere: w('#hemisphere'), lobe: w('#lobe'), polar: w('#polar'), theta: w('#theta'),
             albedo: w('#albedo'), sphere: w('#spheres canvas'), slice: w('#slices canvas') };"""


def wait_laid_out(driver):
    """Until the page has laid its views out for the window's width (200 ms after a resize, later
    on a loaded machine), and their requests have answered."""
    try:
        WebDriverWait(driver, 30).until(lambda d: d.execute_script(
            "return window.halfback.stats.layoutWidth === window.innerWidth;"))
    except Exception:  # pylint: disable=broad-except
        check(False, "the page lays its views out again for the window's new width (30 s)")
    wait_idle(driver)


def check_views_grow(sizes):
    """Every view is larger at 2400 px than at 1100 px, and never smaller at a wider window
    (the hemisphere stayed 256 px, the lobe 400, the polar and albedo plots 460 × 270, and
    the slices shrank at 2400 px)."""
    widths = sorted(sizes)
    for view in sizes[widths[0]]:
        seq = [sizes[w][view] for w in widths]
        check(all(b >= a - 0.5 for a, b in zip(seq, seq[1:])) and seq[-1] > 1.25 * seq[0],
              f"the {view} grows with the window ({', '.join(f'{w}: {s:.0f}' for w, s in zip(widths, seq))} px)")


def given_brdfs_checks(halfback, screenshots):
    """A measured file, a neural BRDF and a sum of models given on the command line."""
    measured = os.path.join(REPO, "data", "rgl", "ilm_l3_37_metallic_rgb.bsdf")
    given = [measured, os.path.join(REPO, "data", "nbrdf", "gold-metallic-paint3.h5"),
             "lambert:albedo=0.2+ggx:alpha=0.15,f0=0.9"]
    names = ["ilm_l3_37_metallic_rgb.bsdf", "gold-metallic-paint3.h5", given[2]]
    with tempfile.TemporaryDirectory() as root:
        shutil.copy(measured, root)
        subprocess.run([sys.executable, os.path.join(REPO, "scripts", "make_mesh.py"),
                        os.path.join(root, "cube.obj"), "--u", "12", "--v", "6"], check=True)
        with open(os.path.join(root, "not-a-brdf.bsdf"), "w") as f:
            f.write("not a BRDF\n")
        proc, base, token = start_server(halfback, given, root)
        driver = make_driver()
        driver.set_script_timeout(300)
        try:
            driver.set_window_size(1600, 1250)
            driver.get(f"{base}?token={token}")
            WebDriverWait(driver, 60).until(lambda d: d.find_element(By.ID, "status").text.startswith("ready"))
            wait_idle(driver)
            guarded(driver, check_given_on_command_line, driver, given, names)
            guarded(driver, check_polar_labels, driver)
            guarded(driver, check_show_hide_solo_colour, driver, names)
            guarded(driver, check_theta_plot, driver, halfback, names, given)
            guarded(driver, check_polar_cosine, driver)
            guarded(driver, check_hemisphere_marks, driver)
            for k in range(3):  # the same three at once whatever the page shows at first
                driver.execute_async_script("Promise.resolve(window.halfback.addBrdf(arguments[0])).then(arguments[1]);", f"arg:{k}")
            wait_idle(driver)
            # One pass of each sphere is enough for the layout; all 32 of a network and a measured
            # file took > 300 s on a loaded 2-core machine.
            driver.execute_async_script("window.halfback.spheresDone(1).then(arguments[0]);")
            sizes = {}
            for width in [1100, 1600, 2400]:
                driver.set_window_size(width, 1250)
                time.sleep(0.5)  # the slices are laid out again 200 ms after a resize
                wait_laid_out(driver)
                sizes[width] = driver.execute_script(VIEW_SIZES)
                check_wraps(driver, width)
                guarded(driver, check_sphere_export, driver, width)
                height = driver.execute_script("return document.documentElement.scrollHeight;")
                driver.set_window_size(width, height + 140)  # the whole page in one picture
                time.sleep(0.5)
                wait_idle(driver)
                driver.execute_script("window.scrollTo(0, 0);")
                for attempt in range(3):  # a tall page on a loaded machine can pass the renderer's 10 s
                    try:
                        driver.save_screenshot(os.path.join(screenshots, f"view-three-{width}.png"))
                        break
                    except Exception as e:  # pylint: disable=broad-except
                        print(f"note: screenshot at {width} px, attempt {attempt + 1}: {type(e).__name__}")
            guarded(driver, check_views_grow, sizes)
            driver.set_window_size(1600, 1250)
            time.sleep(0.5)
            wait_idle(driver)
            guarded(driver, check_one_request_per_view, driver)
            guarded(driver, check_mesh, driver, screenshots)
            guarded(driver, check_mesh_url_and_export, driver, screenshots)
            for name in ["slices", "hemisphere", "polar", "theta", "lobe", "albedo", "sphere", "mesh"]:
                panel = driver.find_element(By.ID, f"{name}-panel")
                driver.execute_script("arguments[0].scrollIntoView({block: 'start'});", panel)
                panel.screenshot(os.path.join(screenshots, f"view-three-{name}.png"))
                save_export_png(driver, name, os.path.join(screenshots, f"view-three-export-{name}.png"))
            driver.execute_script("""const b = document.getElementById('brdf-b');
                if (b.value !== 'arg:1') { b.value = 'arg:1'; b.dispatchEvent(new Event('change')); }
                const s = document.getElementById('mode');
                s.value = 'diff'; s.dispatchEvent(new Event('change'));""")
            wait_idle(driver)
            guarded(driver, check_colourbar_labels, driver, "a file minus a neural BRDF")
            for c in [check_hemisphere_click, check_drag_to_rim, check_typed_text, check_ior_sliders]:
                guarded(driver, c, driver)
            guarded(driver, check_load_box, driver, given, root)
            guarded(driver, check_show_needs_compare, driver)
            guarded(driver, check_eight_brdfs, driver)
            logs = [l for l in driver.get_log("browser") if l["level"] == "SEVERE"
                    and "not-a-brdf" not in l["message"]]  # the refused file's 400: expected
            check(not logs, f"three BRDFs: no errors in the browser console {logs[:3]}")
            guarded(driver, check_lobe_see_through, driver, base, token)
        finally:
            driver.quit()
            proc.send_signal(signal.SIGINT)
            try:
                proc.wait(timeout=10)
            except subprocess.TimeoutExpired:
                proc.kill()


def api_requests(driver):
    """The page's requests so far, by path: {path: count} (Resource Timing)."""
    return driver.execute_script("""const n = {};
        for (const e of performance.getEntriesByType('resource')) {
          const p = new URL(e.name).pathname;
          if (p.startsWith('/api/')) n[p] = (n[p] || 0) + 1;
        }
        return n;""")


def api_brdfs_per_request(driver, path):
    """The number of brdf= of each of the page's requests of `path` so far (Resource Timing)."""
    return driver.execute_script("""const out = [];
        for (const e of performance.getEntriesByType('resource')) {
          const u = new URL(e.name);
          if (u.pathname === arguments[0] && (u.pathname !== '/api/hemisphere' || u.searchParams.get('colour') === 'rho'))
            out.push(u.searchParams.getAll('brdf').length);
        }
        return out;""", path)


def check_one_request_per_view(driver):
    """With three BRDFs shown, an ωo typed (at rest) asks each view's endpoint for every BRDF in
    one request: each /api/polar, /api/pointlight and /api/mesh request names all three, and so
    does the lobe's /api/hemisphere, and there are fewer requests than BRDFs per view (the page before batching
    sent one per BRDF and view). (A view may be drawn twice as the page settles: the count of
    redraws is not what this checks.)"""
    shown = driver.execute_script("return 1 + (window.halfback.state.b ? 1 : 0) + window.halfback.state.more.length;")
    check(shown >= 3, f"one request per view: {shown} BRDFs shown")
    driver.execute_script("performance.setResourceTimingBufferSize(10000); performance.clearResourceTimings();")
    type_into(driver, "theta-o", "33")
    wait_idle(driver)
    # The mesh follows without holding the page's idle(): its request ends when it ends.
    WebDriverWait(driver, 120).until(lambda d: api_requests(d).get("/api/mesh"))
    time.sleep(0.5)
    wait_idle(driver)
    n = api_requests(driver)
    per = {p: api_brdfs_per_request(driver, p)
           for p in ["/api/polar", "/api/pointlight", "/api/mesh", "/api/hemisphere"]}
    views = {"/api/polar": 1, "/api/pointlight": 1, "/api/mesh": 1, "/api/hemisphere": 2}
    # The hemisphere itself shows the first BRDF (or the compared pair); the lobe shows them all.
    batched = all(per[p] and all(k == shown for k in per[p]) for p in per if p != "/api/hemisphere")
    check(batched and shown in per["/api/hemisphere"]
          and all(n.get(p, 0) < views[p] * shown for p in views),
          f"one request per view for {shown} BRDFs when ωo moves, each naming all of them: "
          f"brdf= per request {per}; requests {n}")
    # The slices of every BRDF shown: one /api/slices request per update, moving and at rest
    # (the page before asked one request per two BRDFs).
    driver.execute_script("performance.clearResourceTimings();")
    driver.execute_script("""const s = document.getElementById('azimuth');
        s.value = 40; s.dispatchEvent(new Event('input'));""")
    wait_idle(driver)
    time.sleep(0.6)  # the refinement at rest
    wait_idle(driver)
    rows = driver.execute_script("""const s = window.halfback.state;
        if (s.b && s.mode !== 'a') return 2;  // the pair: second, difference or ratio
        return [s.a, s.b, ...s.more].filter((x) => x && !s.hide.includes(x)).length;""")
    slices = api_brdfs_per_request(driver, "/api/slices")
    check(rows >= 2 and slices and all(k == rows for k in slices),
          f"one /api/slices request per update for the {rows} BRDFs of the slices: "
          f"brdf= per request {slices}")


def check_mesh(driver, screenshots):
    """The lit mesh: one image per BRDF shown, the server's (/api/mesh) as drawn; the environment
    refines by passes; a drag turns it; an OBJ under the root is offered and drawn."""
    def mesh_state():
        return driver.execute_script("""return [...document.querySelectorAll('#meshes canvas')].map((c) =>
            ({ passes: Number(c.dataset.passes || 0), spec: c.dataset.spec, lit: c.sum ? c.sum.filter((v) => v > 0).length : 0 }));""")
    WebDriverWait(driver, 120).until(lambda d: all(m["passes"] >= 1 for m in mesh_state()) and mesh_state())
    shown = driver.execute_script("return 1 + (window.halfback.state.b ? 1 : 0) + window.halfback.state.more.length;")
    state = mesh_state()
    check(len(state) == shown and all(m["lit"] > 1000 for m in state),
          f"lit mesh: an image per BRDF shown ({shown}), each lit: {state}")
    same = driver.execute_async_script("""const done = arguments[0];
        const c = document.getElementById('mesh-0'), q = new URLSearchParams(location.search);
        const p = new URLSearchParams({ brdf: c.dataset.spec, mesh: document.getElementById('mesh-mesh').value,
          size: c.width, yaw: '35.00', pitch: '25.00', light: 'point', theta_l: window.halfback.state.to,
          phi_l: window.halfback.state.po, token: q.get('token') });
        fetch('/api/mesh?' + p).then((r) => r.arrayBuffer()).then((b) => {
          const f = new Float32Array(b);
          let diff = 0;
          for (let k = 0; k < f.length; ++k) diff = Math.max(diff, Math.abs(f[k] - c.sum[k]));
          done([f.length, c.sum.length, diff]);
        });""")
    check(same[0] == same[1] and same[2] == 0, f"lit mesh: the first image is the server's /api/mesh: {same}")
    options = driver.execute_script("return [...document.getElementById('mesh-mesh').options].map((o) => o.value);")
    check(options == ["embedded:rounded-cube", "file:cube.obj"], f"lit mesh: the meshes offered {options}")
    driver.execute_script("arguments[0].scrollIntoView({block: 'start'});", driver.find_element(By.ID, "mesh-panel"))
    total = "const c = document.getElementById('mesh-0'); return c.sum ? [c.sum.length, c.sum.reduce((a, v) => a + v, 0)] : [0, 0];"
    before = driver.execute_script(total)
    canvas = driver.find_element(By.ID, "mesh-0")
    ActionChains(driver).move_to_element(canvas).click_and_hold().move_by_offset(60, 20).release().perform()
    turned = WebDriverWait(driver, 120).until(
        lambda d: (lambda now: now[0] == before[0] and now[1] != before[1])(d.execute_script(total)))
    check(turned, "lit mesh: a drag turns the mesh")
    driver.execute_script("""const s = document.getElementById('mesh-light'); s.value = 'env'; s.dispatchEvent(new Event('change'));""")
    WebDriverWait(driver, 240).until(lambda d: all(m["passes"] >= 2 for m in mesh_state()))
    check(True, "lit mesh: the environment refines by passes")
    driver.find_element(By.ID, "mesh-panel").screenshot(os.path.join(screenshots, "view-three-mesh-env.png"))
    driver.execute_script("""const s = document.getElementById('mesh-mesh'); s.value = 'file:cube.obj'; s.dispatchEvent(new Event('change'));
        const l = document.getElementById('mesh-light'); l.value = 'point'; l.dispatchEvent(new Event('change'));""")
    WebDriverWait(driver, 120).until(lambda d: all(m["passes"] == 1 for m in mesh_state()))
    check(all(m["lit"] > 1000 for m in mesh_state()), "lit mesh: an OBJ under the root is drawn")


def check_mesh_url_and_export(driver, screenshots):
    """The lit mesh's settings (mesh, light, yaw, pitch, size) are in the URL: reloaded, the page
    shows the same images; its export is a figure titled with them, and its PNG is twice the
    figure's size (saved as view-three-mesh-export.png)."""
    import base64
    import struct
    driver.execute_script("""const s = document.getElementById('mesh-size'); s.value = '384'; s.dispatchEvent(new Event('change'));""")
    def images():
        return driver.execute_script("""return [...document.querySelectorAll('#meshes canvas')].map((c) =>
            [c.width, c.style.width, Number(c.dataset.passes || 0), c.sum ? Array.from(c.sum.filter((_, k) => k % 97 === 0)) : null]);""")
    WebDriverWait(driver, 120).until(lambda d: (lambda m: m and all(x[0] == 384 and x[2] == 1 for x in m))(images()))
    before = images()
    time.sleep(0.3)  # the fragment is written at most ten times a second
    url = driver.current_url
    fragment = urllib.parse.parse_qs(url.split("#", 1)[1])
    settings = {k: fragment.get(k, [None])[0] for k in ["mesh", "meshLight", "meshYaw", "meshPitch", "meshSize"]}
    check(settings["mesh"] == "file:cube.obj" and settings["meshLight"] == "point" and settings["meshSize"] == "384"
          and settings["meshYaw"] not in (None, "35") and settings["meshPitch"] is not None,
          f"lit mesh: its settings are in the URL ({settings})")
    got = driver.execute_async_script("""const done = arguments[0];
        const p = document.getElementById('mesh-panel').getBoundingClientRect();
        window.halfback.figurePng('mesh').then((png) => done({ png, panel: [p.width, p.height], svg: window.halfback.figure('mesh') }))
          .catch((e) => done({ error: e.message }));""")
    check("png" in got, f"lit mesh: the export makes a PNG ({got.get('error')})")
    if "png" in got:
        data = base64.b64decode(got["png"].split(",", 1)[1])
        with open(os.path.join(screenshots, "view-three-mesh-export.png"), "wb") as f:
            f.write(data)
        width, height = struct.unpack(">II", data[16:24])
        svg_w, svg_h = (int(x) for x in re.search(r'<svg[^>]* width="(\d+)" height="(\d+)"', got["svg"]).groups())
        pw, ph = got["panel"]
        # The figure: the panel's height under a title of one or more lines (10 + 18 px each), as
        # wide as what it shows (at most the panel, at least 360 px).
        check(data[:8] == b"\x89PNG\r\n\x1a\n" and (width, height) == (2 * svg_w, 2 * svg_h)
              and any(svg_h == math.ceil(ph + 10 + 18 * k) for k in range(1, 5))
              and 360 <= svg_w <= math.ceil(pw) and len(re.findall("<image", got["svg"])) == len(before),
              f"lit mesh: the PNG export is twice the figure ({width} x {height}; figure {svg_w} x {svg_h}, "
              f"panel {pw:.0f} x {ph:.0f}, {len(before)} images)")
        title = re.search(r"<text[^>]*>([^<]*)</text>", got["svg"]).group(1)
        check("lit mesh cube.obj turned" in title and "point light from ωo" in title and "ilm_l3_37_metallic_rgb.bsdf" in title,
              f"lit mesh: the figure's title names the mesh, its turn, the light and the BRDFs ({title})")
    driver.refresh()
    WebDriverWait(driver, 120).until(lambda d: d.find_element(By.ID, "status").text.startswith("ready"))
    status = driver.find_element(By.ID, "status").text
    WebDriverWait(driver, 120).until(lambda d: (lambda m: m and all(x[2] == 1 for x in m))(images()))
    after = images()
    shown = driver.execute_script("""return ['mesh-mesh', 'mesh-light', 'mesh-size'].map((id) => document.getElementById(id).value);""")
    check(after == before and shown == ["file:cube.obj", "point", "384"] and status == "ready",
          f"lit mesh: the URL reloads to the same images ({shown}, {len(after)} images the same: "
          f"{after == before}; status {status!r})")
    wait_idle(driver)
    driver.execute_async_script("window.halfback.spheresDone(1).then(arguments[0]);")
    # Settings a URL may give that the page does not offer: each named, its default shown.
    got = driver.execute_async_script("""const done = arguments[0];
        import('/static/mesh.js').then((m) => {
          const settings = { ...m.MESH_DEFAULTS, mesh: 'file:none.obj', meshLight: 'sun', meshYaw: 500, meshPitch: NaN, meshSize: 77 };
          const view = new m.MeshView(document.createElement('section'), { meshes: ['embedded:rounded-cube', 'file:cube.obj'],
            colours: [], label: (s) => s, title: (s) => s, swatch: () => '', onError: () => {}, settings, onSettings: () => {} });
          done([view.settingsNote, settings]);
        }).catch((e) => done([e.message, null]));""")
    note, fixed = got
    check(fixed == {"mesh": "embedded:rounded-cube", "meshLight": "point", "meshYaw": 35, "meshPitch": 25, "meshSize": 256}
          and all(w in note for w in ["mesh 'file:none.obj'", "meshLight 'sun'", "meshYaw '500'", "meshPitch 'NaN'", "meshSize '77'"]),
          f"lit mesh: settings not offered are named and replaced by their defaults ({note!r}, {fixed})")


def guarded(driver, check_fn, *args):
    """A check that fails on its own: an exception is its failure, the next one still runs."""
    try:
        check_fn(*args)
    except Exception as e:  # pylint: disable=broad-except
        check(False, f"{check_fn.__name__}: {type(e).__name__} {str(e)[:200]}")
        ActionChains(driver).release().perform()
        wait_idle(driver)


if __name__ == "__main__":
    main()
