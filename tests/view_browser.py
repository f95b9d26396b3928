#!/usr/bin/env python3
"""The page of `femdyn view` in a real browser: headless Chromium (Debian's `chromium`).

usage: view_browser.py FEMDYN SOURCE_DIR WORK_DIR CASE
       (CASE: finger, hand, arm7, meshes, loop, urdf_meshes or flexible)

For the case's model it simulates a short trajectory, writes the page of one posture and the
page of the trajectory, and in one headless Chromium (driven over the DevTools protocol):
  - loads each page and reads the status element the page fills (web/view.js): no JavaScript
    error, WebGL up, and the numbers of bodies, moving joints, elements, named frames and URDF
    visuals it drew equal to those femdyn reports for the model (`femdyn info --json`; the
    visuals counted in the URDF here);
  - takes screenshots of the trajectory's 3-D view at #t=0 and at its last time: not blank,
    and different from each other;
  - moves the mouse over named objects: the tooltip names a body of the model;
  - meshes (MJCF, floating base) and urdf_meshes (URDF: relative, package:// and Collada meshes,
    one on a welded link): the visuals and distinct meshes drawn equal those the file holds,
    counted here from the XML;
  - loop (a five-bar closed by a ball constraint): every constraint of `femdyn info` is drawn,
    its two places together (within 1e-4 of the model's size) at every screenshot; the model is
    renamed with quotes, a backslash, markup and a script end tag, which the page's title and
    model line show exactly as `femdyn info` names it;
  - flexible (the flexible space robot, started bent, its joints driven): each flexible bar of
    `femdyn info` is drawn as a tube along its centreline: every vertex within its radius (and
    the curve's bow off a chord) of the polyline through the bar's stations at every
    screenshot, where at t = 0 the stations stand off the clamp-to-tip chord by more than twice
    the radius (so a straight tube would fail);
  - finger, again in a Chromium without WebGL (--disable-3d-apis): the page says so, holds the
    same counts and draws its plots.
Exit 77 (ctest's SKIP_RETURN_CODE) when Chromium is absent; tools/setup.sh --all installs it.
"""
import base64
import fnmatch
import json
import math
import os
import select
import shutil
import struct
import subprocess
import sys
import time
import xml.etree.ElementTree as ET
import zlib

SKIP = 77
HOSTILE_NAME = 'q"uote\'s \\ back <b>&amp;</b> </script><!-- ${x}'

WIDTH, HEIGHT = 960, 600  # the browser's view
VIEW3D = 960 - 340  # the 3-D view's width: left of the side panel (web/view.html #side, 340 px)
BACKGROUND = (0xF4, 0xF6, 0xF8)  # the 3-D view's clear colour (web/view.js)

# Each case: the model, and the simulate options of its trajectory (enough motion to see).
CASES = {
    "finger": ("models/finger.json", ["--t-end", "0.3", "--tau-each", "0.002", "--every", "10"]),
    "hand": ("models/hand.json", ["--t-end", "0.6", "--every", "10"]),
    "arm7": ("models/urdf/arm7.urdf",
             ["--t-end", "0.6", "--q0", "0.3,0.6,0,0.8,0,0,0", "--every", "10"]),
    "meshes": ("tests/data/mjcf/meshes.xml", ["--t-end", "0.4", "--every", "10"]),
    "loop": ("models/five_bar.json", ["--t-end", "0.6", "--every", "10"]),
    "urdf_meshes": ("tests/data/urdf/meshed/meshed_arm.urdf",
                    ["--t-end", "0.6", "--q0", "0.5,0.2", "--every", "10"]),
    "flexible": ("models/flexible_space_robot.json",
                 ["--t-end", "0.3", "--tau-on", "shoulder=400,elbow=-300",
                  "--bent", "upper.*.rz=0.1,fore.*.ry=0.08", "--every", "10"]),
}


def chromium():
    for name in (os.environ.get("FEMDYN_CHROMIUM"), "chromium", "chromium-browser"):
        if name and shutil.which(name):
            return shutil.which(name)
    return None


def run(cmd, **kw):
    r = subprocess.run(cmd, capture_output=True, text=True, timeout=120, **kw)
    if r.returncode != 0:
        raise AssertionError(f"{' '.join(cmd)} failed ({r.returncode}): {r.stderr.strip()}")
    return r.stdout


class Chromium:
    """Headless Chromium driven over the DevTools protocol on a pipe (--remote-debugging-pipe:
    JSON messages ending in a NUL byte, written to its fd 3 and read from its fd 4): one browser
    for every page of a case. Software WebGL (SwiftShader); a fixed WIDTH x HEIGHT view."""

    def __init__(self, exe, profile, extra_flags=()):
        self.log = profile + ".log"  # Chromium's messages, quoted when it fails
        self._log = open(self.log, "w")
        to_chrome, self._out = os.pipe()
        self._in, from_chrome = os.pipe()

        def child_fds():  # the protocol's fds 3 and 4 in the child
            os.dup2(to_chrome, 3)
            os.dup2(from_chrome, 4)

        self.proc = subprocess.Popen(
            [exe, "--headless", "--no-sandbox", "--disable-gpu", "--disable-dev-shm-usage",
             "--use-angle=swiftshader",
             "--enable-unsafe-swiftshader", "--no-first-run", "--disable-extensions",
             "--remote-debugging-pipe", f"--user-data-dir={profile}",
             f"--window-size={WIDTH},{HEIGHT}",
             "--hide-scrollbars", *extra_flags, "about:blank"],
            stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL, stderr=self._log,
            preexec_fn=child_fds, pass_fds=(3, 4))
        os.close(to_chrome)
        os.close(from_chrome)
        self._buffer, self._id, self.session = b"", 0, None
        target = self.call("Target.createTarget", url="about:blank")["targetId"]
        self.session = self.call("Target.attachToTarget", targetId=target,
                                 flatten=True)["sessionId"]
        self.call("Emulation.setDeviceMetricsOverride", width=WIDTH, height=HEIGHT,
                  deviceScaleFactor=1, mobile=False)

    def call(self, method, timeout=60, **params):
        self._id += 1
        message = {"id": self._id, "method": method, "params": params}
        if self.session:
            message["sessionId"] = self.session
        os.write(self._out, json.dumps(message).encode() + b"\0")
        deadline = time.monotonic() + timeout
        while True:
            while b"\0" not in self._buffer:
                left = deadline - time.monotonic()
                if left <= 0 or not select.select([self._in], [], [], left)[0]:
                    raise AssertionError(f"chromium: no answer to {method} in {timeout} s")
                chunk = os.read(self._in, 1 << 20)
                if not chunk:
                    tail = open(self.log).read().strip().splitlines()[-5:]
                    raise AssertionError(f"chromium exited while answering {method}: {tail}")
                self._buffer += chunk
            raw, self._buffer = self._buffer.split(b"\0", 1)
            reply = json.loads(raw)
            if reply.get("id") == self._id:  # events (no id) are passed over
                if "error" in reply:
                    raise AssertionError(f"chromium: {method}: {reply['error']}")
                return reply["result"]

    def evaluate(self, expression):
        result = self.call("Runtime.evaluate", expression=expression, returnByValue=True,
                           awaitPromise=True)
        if "exceptionDetails" in result:
            raise AssertionError(f"{expression}: {result['exceptionDetails']}")
        return result["result"].get("value")

    def open(self, url):
        """Loads the page and waits until its script has set its status (at most 30 s)."""
        self.call("Page.navigate", url=url)
        deadline, state = time.monotonic() + 30, ""
        while time.monotonic() < deadline:
            state = self.evaluate("document.readyState + ' ' + (document.getElementById("
                                  "'femdyn-status') || {dataset: {}}).dataset.status")
            if state.startswith("complete") and not state.endswith(("loading", "undefined")):
                return
            time.sleep(0.05)
        raise AssertionError(f"{url}: the page did not finish loading in 30 s ({state})")

    def status(self):
        """The status element's data attributes and text, and window.femdynErrors."""
        return self.evaluate("""(() => {
            const s = document.getElementById('femdyn-status');
            return {data: Object.assign({}, s.dataset), text: s.textContent,
                    errors: window.femdynErrors};
        })()""")

    def screenshot_at(self, t, path):
        """The 3-D view at time t (the page's #t= hash: paused there) after two animation
        frames, at half scale (enough to see it move, and quick to read)."""
        self.evaluate(f"window.location.hash = 't={t}'")
        self.evaluate("new Promise(r => requestAnimationFrame(() => requestAnimationFrame(r)))")
        clip = {"x": 0, "y": 0, "width": VIEW3D, "height": HEIGHT, "scale": 0.5}
        shot = self.call("Page.captureScreenshot", format="png", clip=clip)["data"]
        with open(path, "wb") as f:
            f.write(base64.b64decode(shot))

    def hover(self, x, y):
        """Moves the mouse to (x, y); the text of the page's tooltip then, or None."""
        self.call("Input.dispatchMouseEvent", type="mouseMoved", x=x, y=y)
        # (Chromium delivers pointermove with the next animation frame: two frames, then read)
        self.evaluate("new Promise(r => requestAnimationFrame(() => requestAnimationFrame(r)))")
        return self.evaluate("(() => { const t = document.getElementById('tooltip');"
                             " return t.style.display === 'block' ? t.textContent : null; })()")

    def close(self):
        try:
            self.session = None
            self.call("Browser.close", timeout=10)
        except AssertionError:
            pass
        try:
            self.proc.wait(timeout=10)
        except subprocess.TimeoutExpired:
            self.proc.kill()
            self.proc.wait()
        os.close(self._out)
        os.close(self._in)
        self._log.close()


def png_pixels(path):
    """(width, height, rows of RGB tuples) of an 8-bit RGB or RGBA PNG (Chromium's screenshots)."""
    data = open(path, "rb").read()
    assert data[:8] == b"\x89PNG\r\n\x1a\n", f"{path}: not a PNG"
    pos, idat = 8, b""
    while pos < len(data):
        (length,), kind = struct.unpack(">I", data[pos:pos + 4]), data[pos + 4:pos + 8]
        body = data[pos + 8:pos + 8 + length]
        if kind == b"IHDR":
            width, height, depth, color = struct.unpack(">IIBB", body[:10])
        elif kind == b"IDAT":
            idat += body
        pos += 12 + length
    assert depth == 8 and color in (2, 6), f"{path}: PNG colour type {color}, depth {depth}"
    step = 3 if color == 2 else 4
    raw, stride = zlib.decompress(idat), width * step
    rows, prev = [], bytearray(stride)
    for y in range(height):
        f, line = raw[y * (stride + 1)], bytearray(raw[y * (stride + 1) + 1:(y + 1) * (stride + 1)])
        for i in range(stride):  # PNG filters: None, Sub, Up, Average, Paeth
            a = line[i - step] if i >= step else 0
            b, c = prev[i], prev[i - step] if i >= step else 0
            if f == 1:
                line[i] = (line[i] + a) & 255
            elif f == 2:
                line[i] = (line[i] + b) & 255
            elif f == 3:
                line[i] = (line[i] + (a + b) // 2) & 255
            elif f == 4:
                p = a + b - c
                pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
                line[i] = (line[i] + (a if pa <= pb and pa <= pc else b if pb <= pc else c)) & 255
        rows.append([tuple(line[x * step:x * step + 3]) for x in range(width)])
        prev = line
    return width, height, rows


def expected_counts(femdyn, model, source_dir):
    info = json.loads(run([femdyn, "info", model, "--json"], cwd=source_dir))
    bodies = len(info["joints"])  # one joint per body
    counts = {
        "bodies": bodies,
        "joints": sum(j["type"] != "fixed" for j in info["joints"]),
        "elements": len(info["elements"]),
        "frames": len(info["frames"]) - bodies,  # the named ones, after the bodies' own
        "visuals": 0,
    }
    if model.endswith(".urdf"):
        robot = ET.parse(os.path.join(source_dir, model)).getroot()
        counts["visuals"] = len(robot.findall("./link/visual"))
        meshes = {(m.get("filename"), m.get("scale")) for m in robot.iter("mesh")}
        counts["meshes"] = len(meshes)
    if model.endswith(".xml"):  # MJCF: the geoms MuJoCo's viewer draws (no class defaults here)
        root = ET.parse(os.path.join(source_dir, model)).getroot()
        inline = {m.get("name") for m in root.find("asset").iter("mesh") if m.get("file") is None}
        geoms = [g for g in root.find("worldbody").iter("geom")
                 if int(g.get("group", "0")) <= 2 and g.get("type") not in ("plane", "hfield")]
        counts["visuals"] = sum(g.get("mesh") not in inline for g in geoms)
        counts["not_drawn"] = sum(g.get("mesh") in inline for g in geoms)
        counts["meshes"] = len({g.get("mesh") for g in geoms if g.get("mesh")} - inline)
    counts["constraints"] = sum(c["type"] != "gear" for c in info.get("constraints", []))
    counts["bars"] = len(info.get("bars", []))
    return info, counts


def check_status(status, counts, frames_min, page, webgl=True):
    where, data = os.path.basename(page), status["data"]
    assert not status["errors"], f"{where}: JavaScript errors: {status['errors']}"
    assert data.get("status") == "ok", f"{where}: status {data.get('status')}: {status['text']}"
    want = "true" if webgl else "false"
    assert data.get("webgl") == want, f"{where}: WebGL {data.get('webgl')}, expected {want}"
    for key, want in counts.items():
        got = data.get(key)
        assert got == str(want), f"{where}: the page drew {got} {key}, femdyn reports {want}"
    assert int(data["motionFrames"]) >= frames_min, f"{where}: {data['motionFrames']} frames"


def check_name(browser, name, page):
    assert name == HOSTILE_NAME, f"femdyn info names the model {name!r}"
    title = browser.evaluate("document.title")
    line = browser.evaluate("document.getElementById('model-name').textContent")
    assert title == "femdyn view: " + name, f"{page}: the title is {title!r}"
    assert line.startswith(name + " ("), f"{page}: the model line is {line!r}"


def check_screenshots(case, shots, times):
    for t, shot in zip(times, shots):
        pixels = [p for row in shot for p in row]
        drawn = sum(p != BACKGROUND for p in pixels) / len(pixels)
        assert drawn > 0.005, f"{case}: the 3-D view at t = {t} is blank ({drawn:.2%} drawn)"
    changed = sum(a != b for ra, rb in zip(*shots) for a, b in zip(ra, rb))
    share = changed / sum(len(r) for r in shots[0])
    assert share > 0.002, f"{case}: the 3-D view at t = {times[0]} and {times[1]} are the same"
    return share


def check_hover(browser, info, case):
    """The mouse over an element names it and its body (a body of the model)."""
    bodies = {j["body"] for j in info["joints"]}
    spots = [s for s in browser.evaluate("window.femdynView.labelsOnScreen()")
             if 0 < s["x"] < VIEW3D and 0 < s["y"] < HEIGHT]
    assert spots, f"{case}: nothing named on the screen"
    names, named = [], []
    for s in spots[:20]:  # (a ring's centre, a joint's, may have nothing under it)
        names.append(browser.hover(s["x"], s["y"]))
        named = [n for n in names if n and any(b in n for b in bodies)]
        if named:
            break
    assert named, f"{case}: hovering named no body of the model: {names}"
    return named[0]


def check_closures(browser, counts, case, t):
    """Each loop constraint drawn with its two places together (a closed loop, drawn closed)."""
    closures = browser.evaluate("window.femdynView.closures()")
    assert len(closures) == counts["constraints"], f"{case}: {len(closures)} closures drawn"
    for c in closures:
        assert c["distance"] <= 1e-4 * c["extent"], \
            f"{case}: at t = {t} a loop is drawn open by {c['distance']:.3g} m"
    return len(closures)


def segment_distance(p, a, b):
    ab = [y - x for x, y in zip(a, b)]
    ap = [y - x for x, y in zip(a, p)]
    s = max(0.0, min(1.0, sum(x * y for x, y in zip(ab, ap)) / max(sum(x * x for x in ab), 1e-30)))
    return sum((x + s * d - y) ** 2 for x, d, y in zip(a, ab, p)) ** 0.5


def check_bars(browser, counts, case, t, bent):
    """Each flexible bar drawn along its centreline: a tube about the polyline through its
    stations, from the clamp to the tip."""
    bars = browser.evaluate("window.femdynView.bars()")
    assert len(bars) == counts["bars"], f"{case}: {len(bars)} bars drawn"
    for bar in bars:
        s, r = bar["stations"], bar["radius"]
        # The curve bows off each chord by about its sagitta, c θ / 8 for a chord c between
        # turns of θ: allowed twice that, with the longest chord and the largest turn.
        chords = [[y - x for x, y in zip(s[i], s[i + 1])] for i in range(len(s) - 1)]
        length = [sum(x * x for x in c) ** 0.5 for c in chords]
        turn = max(math.acos(max(-1.0, min(1.0, sum(x * y for x, y in zip(a, b)) / (la * lb))))
                   for a, b, la, lb in zip(chords, chords[1:], length, length[1:]))
        bow = max(length) * turn / 4
        # (bent: the stations stand off the chord from clamp to tip by more than the radius, so
        # a straight tube would fail the test below)
        bend = max(segment_distance(p, s[0], s[-1]) for p in s)
        assert bar["vertices"], f"{case}: a bar without a tube"
        far = max(min(segment_distance(v, s[i], s[i + 1]) for i in range(len(s) - 1))
                  for v in bar["vertices"])
        assert far <= r * 1.001 + bow, \
            f"{case}: at t = {t} the tube strays {far:.3g} m from its centreline (radius {r:.3g})"
        assert bend > 2 * r or not bent, f"{case}: at t = {t} a bar bends by {bend:.3g} m only"
    return len(bars)


def check_without_webgl(exe, work, page, counts, case):
    """The page in a Chromium without WebGL: it says so, holds the scene and draws its plots."""
    browser = Chromium(exe, os.path.join(work, "profile-nogl"), ["--disable-3d-apis"])
    try:
        browser.open(f"file://{page}")
        check_status(browser.status(), counts, 1, page, webgl=False)
        note = browser.evaluate("(document.getElementById('no-webgl') || {}).textContent || ''")
        assert "no WebGL" in note, f"{case}: without WebGL the page does not say so: {note!r}"
        ink = browser.evaluate("window.femdynView.plotInk()")
        assert all(share > 0.002 for share in ink), f"{case}: plots blank without WebGL: {ink}"
    finally:
        browser.close()


def main():
    if len(sys.argv) != 5 or sys.argv[4] not in CASES:
        print(__doc__)
        return 2
    femdyn, source_dir, work, case = sys.argv[1:]
    exe = chromium()
    if exe is None:
        print("SKIP: chromium not found (Debian's chromium; tools/setup.sh --all installs it)")
        return SKIP
    start = time.monotonic()
    work = os.path.join(os.path.abspath(work), case)
    shutil.rmtree(work, ignore_errors=True)
    os.makedirs(work)
    model, simulate = CASES[case]
    if case == "loop":  # a name that HTML, the script block and JSON must each escape
        doc = json.load(open(os.path.join(source_dir, model)))
        doc["name"] = HOSTILE_NAME
        doc.pop("$schema", None)
        model = os.path.join(work, "renamed.json")
        with open(model, "w") as f:
            json.dump(doc, f)
    info, counts = expected_counts(femdyn, model, source_dir)
    if "--tau-on" in simulate:  # an actuation on named coordinates, zero on the others
        k = simulate.index("--tau-on")
        on = dict(x.split("=") for x in simulate[k + 1].split(","))
        simulate[k:k + 2] = ["--tau", ",".join(on.get(c, "0") for c in info["coordinates"])]
    if "--bent" in simulate:  # a floating base at rest (x, y, z, qw … qz), then these angles
        k = simulate.index("--bent")
        on = [x.split("=") for x in simulate[k + 1].split(",")]
        angle = [next((float(v) for p, v in on if fnmatch.fnmatch(c, p)), 0.0)
                 for c in info["coordinates"][6:]]
        simulate[k:k + 2] = ["--q0", ",".join(map(str, [0, 0, 0, 1, 0, 0, 0] + angle))]
    if "--tau-each" in simulate:  # the same actuation on every coordinate
        k = simulate.index("--tau-each")
        simulate[k:k + 2] = ["--tau", ",".join([simulate[k + 1]] * info["n"])]

    traj = os.path.join(work, "traj.csv")
    run([femdyn, "simulate", model, *simulate, "--out", traj], cwd=source_dir)
    times = (0.0, float(open(traj).read().strip().splitlines()[-1].split(",")[0]))
    posture, moving = os.path.join(work, "posture.html"), os.path.join(work, "motion.html")
    run([femdyn, "view", model, "--out", posture], cwd=source_dir)
    run([femdyn, "view", model, "--traj", traj, "--out", moving], cwd=source_dir)

    browser = Chromium(exe, os.path.join(work, "profile"))
    try:
        shots = []
        for page, frames_min in ((posture, 1), (moving, 2)):
            browser.open(f"file://{page}")
            check_status(browser.status(), counts, frames_min, page)
            if case == "loop":
                check_name(browser, info["model"], page)
        closures = 0
        for t in times:
            png = os.path.join(work, f"t{t:g}.png")
            browser.screenshot_at(t, png)
            shots.append(png_pixels(png)[2])
            closures = check_closures(browser, counts, case, t)
            check_bars(browser, counts, case, t, bent=t == times[0])
        hovered = check_hover(browser, info, case)
        assert not browser.status()["errors"], f"{case}: JavaScript errors while playing"
    finally:
        browser.close()
    share = check_screenshots(case, shots, times)
    if case == "finger":
        check_without_webgl(exe, work, posture, counts, case)
    print(f"{case}: {counts}; page {os.path.getsize(moving) / 1e6:.2f} MB; {share:.1%} of the "
          f"view changed from t = 0 to {times[1]}; {closures} loops drawn closed; "
          f"hover: {hovered!r}; {time.monotonic() - start:.1f} s")
    return 0


if __name__ == "__main__":
    try:
        sys.exit(main())
    except AssertionError as e:
        print(f"FAIL: {e}")
        sys.exit(1)
