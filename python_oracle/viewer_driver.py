"""Drives the glassdb viewer page in headless Chromium through WebDriver (selenium).

    viewer_driver.py check URL [--swap ID:PRODUCT ...] [--out FILE.rgba]
        Opens the page, waits for its first frame, swaps each product through the page's own
        controls (click the glass in the list, type in the search box, click the product), waits
        for the new frame, and writes the canvas's RGBA bytes (rows top to bottom) to --out.
        Prints JSON: size, frames drawn, the product sets, the last swap's time, page errors.

    viewer_driver.py bench URL --id ID --products 'P1|P2' [--repeat N] [--unit 'P1|GAP_MM:GAS|P2']
        Times product choices through the page's automation hook: from the choice to the new
        frame drawn (a 1-pixel read-back finishes the drawing), the CPU time of the browser's
        processes per choice (`swap_cpu_ms`: the first choice of each product not counted; load
        moves it much less than the wall time), a choice for ID right after one for another glass
        of the frame (`switch_ms_median`, 3 times), and the page's load time. With
        --unit, also units built on the page (the hook the builder's button calls) for glass ID,
        the gap widened by 0.1 mm each time so that every build is new: from the request to the
        frame on screen, and the server's share (stack engine, fit, table).

    viewer_driver.py rebind URL --name NAME
        A page of another site against the viewer at URL: Chromium resolves NAME to the
        viewer's address (as after DNS rebinding) and opens http://NAME:PORT/. Prints JSON: the
        text that page got, the status of its own fetch of /api/scene, and whether its
        cross-site text/plain POST of an export to URL was answered (an opaque reply says
        nothing, so the caller checks the export folder).

    viewer_driver.py export URL
        Opens the page, clicks its export button and prints JSON: the status line it shows.

    viewer_driver.py unit URL --glass ID --panes 'P1|GAP_MM:GAS|P2' [--flip K] [--out FILE.rgba]
        Builds a unit through the page's own controls: clicks glass ID in the list, chooses each
        pane's catalog glass (by id) and each gap's width (typed; `nan` clears the box) and gas
        on the unit builder, ticks "flip" of pane K (1: outer; repeatable), clicks "build" and
        waits for its answer. Prints JSON: the builder's status line, the time from the click to
        the frame on screen (and the server's share), the product sets, page errors; writes the
        canvas to --out.

    viewer_driver.py layout URL [--run JS ...] [--window WxH] [--screenshot FILE.png]
        Opens the page, runs each JS snippet (awaited; `window.glassdb` hooks; what each returns,
        or {"thrown": message}, is in `results`), and prints JSON
        of what a designer sees: the window, the stage and the canvas's on-screen box, every
        product and glass name whose text is cut (wider than the box it is shown in, or beyond
        its list's edge) and whether it has a tooltip, and what lies on screen where the A/B
        split line should be (the element there and its colour against the pixels beside it).

Chromium runs as Debian ships it (/usr/bin/chromium, /usr/bin/chromedriver), WebGL2 on
SwiftShader when there is no GPU.
"""

import argparse
import base64
import contextlib
import json
import os
import sys
import time
import urllib.parse

from selenium import webdriver
from selenium.webdriver.chrome.service import Service
from selenium.webdriver.common.by import By
from selenium.webdriver.support.ui import WebDriverWait

CHROMIUM = "/usr/bin/chromium"
CHROMEDRIVER = "/usr/bin/chromedriver"


def browser(gpu, extra=()):
    options = webdriver.ChromeOptions()
    options.binary_location = CHROMIUM
    for flag in ["--headless=new", "--no-sandbox", "--disable-dev-shm-usage",
                 "--allow-file-access-from-files", "--window-size=1400,1000"]:
        options.add_argument(flag)
    if not gpu:
        for flag in ["--use-angle=swiftshader", "--enable-unsafe-swiftshader"]:
            options.add_argument(flag)
    for flag in extra:
        options.add_argument(flag)
    return webdriver.Chrome(service=Service(CHROMEDRIVER), options=options)


def wait_ready(driver, timeout):
    try:
        WebDriverWait(driver, timeout).until(lambda d: d.execute_script("return window.glassdbReady === true"))
    except Exception:
        state = driver.execute_script(
            "return [document.getElementById('status').textContent, typeof window.glassdb,"
            " performance.getEntriesByType('resource').map(e => e.name)]")
        log = driver.get_log("browser")
        raise SystemExit(f"the page did not get ready: status, hooks, loaded: {state}; browser log: {log}")
    errors = driver.execute_script("return window.glassdbErrors || []")
    if errors:
        raise SystemExit("page errors: " + "; ".join(errors))


def renderer(driver):
    """The WebGL2 renderer's name (SwiftShader or the GPU), or None where the browser hides it."""
    return driver.execute_script(
        "const gl = document.createElement('canvas').getContext('webgl2');"
        "const e = gl && gl.getExtension('WEBGL_debug_renderer_info');"
        "return e ? gl.getParameter(e.UNMASKED_RENDERER_WEBGL) : null;")


def drawn(driver):
    return int(driver.execute_script("return window.glassdbFrameDrawn || 0"))


def swap_through_ui(driver, spec, timeout):
    glass_id, name = spec.split(":", 1)
    products = driver.execute_script("return window.glassdb.scene.products")
    matches = [p for p in products if p["name"] == name]
    if len(matches) != 1:
        raise SystemExit(f"no product named {name!r}")
    before = drawn(driver)
    driver.find_element(By.CSS_SELECTOR, f'#glasses li[data-id="{int(glass_id)}"]').click()
    search = driver.find_element(By.ID, "search")
    search.clear()
    search.send_keys(name[:12])
    driver.find_element(By.CSS_SELECTOR, f'#products li[data-index="{matches[0]["index"]}"]').click()
    WebDriverWait(driver, timeout).until(lambda d: drawn(d) > before)


@contextlib.contextmanager
def ready_page(args, extra=()):
    """A headless Chromium on `args.url` once the viewer says it is ready; quit on the way out."""
    driver = browser(args.gpu, extra)
    try:
        driver.get(args.url)
        wait_ready(driver, args.timeout)
        yield driver
    finally:
        driver.quit()


def check(args):
    with ready_page(args) as driver:
        for spec in args.swap:
            swap_through_ui(driver, spec, args.timeout)
        scene = driver.execute_script("return {w: window.glassdb.scene.width, h: window.glassdb.scene.height}")
        pixels = base64.b64decode(driver.execute_script("return window.glassdb.readPixels()"))
        if args.out:
            with open(args.out, "wb") as f:
                f.write(pixels)
        report = {
            "width": scene["w"],
            "height": scene["h"],
            "drawn": drawn(driver),
            "marker": driver.find_element(By.ID, "view-canvas").get_attribute("data-drawn"),
            "products": driver.execute_script("return window.glassdbProducts()"),
            "swap_ms": driver.execute_script("return window.glassdb.lastSwapMs()"),
            "errors": driver.execute_script("return window.glassdbErrors"),
            "renderer": renderer(driver),
        }
        print(json.dumps(report))


def browser_cpu_s(driver):
    """CPU seconds (user + system) so far of the browser's processes: chromedriver's descendants
    (SwiftShader draws in Chromium's GPU process). Less moved by other load than wall time."""
    children = {}
    for entry in os.listdir("/proc"):
        if not entry.isdigit():
            continue
        try:
            with open(f"/proc/{entry}/stat") as f:
                fields = f.read().rsplit(")", 1)[1].split()
        except OSError:
            continue
        # after the name: state, ppid, ..., utime (11), stime (12) counted from state at 0
        children.setdefault(int(fields[1]), []).append((int(entry), int(fields[11]) + int(fields[12])))
    ticks, todo = 0, [driver.service.process.pid]
    while todo:
        for pid, t in children.get(todo.pop(), []):
            ticks += t
            todo.append(pid)
    return ticks / os.sysconf("SC_CLK_TCK")


def bench(args):
    driver = browser(args.gpu)
    try:
        t0 = time.perf_counter()
        driver.get(args.url)
        wait_ready(driver, args.timeout)
        load_ms = (time.perf_counter() - t0) * 1e3
        page_ms = driver.execute_script("return window.glassdbReadyMs")
        products = args.products.split("|")
        swaps = []
        # The first choice of each product is not counted in the CPU time (first uses).
        for p in products:
            driver.execute_script("window.glassdb.choose(arguments[0], arguments[1])", args.id, p)
        cpu0 = browser_cpu_s(driver)
        for k in range(args.repeat):
            for p in products:
                ms = driver.execute_script(
                    "return window.glassdb.choose(arguments[0], arguments[1])", args.id, p)
                swaps.append(ms)
        cpu_ms = (browser_cpu_s(driver) - cpu0) * 1e3 / len(swaps)
        swaps.sort()
        # A choice for ID right after one for another glass of the frame (on a frame with light
        # parts the page then sums the other parts again: docs/viewer.md, "Relit swap").
        others = [int(e.get_attribute("data-id")) for e in driver.find_elements(By.CSS_SELECTOR, "#glasses li")]
        others = [i for i in others if i != args.id]
        switches = []
        for k in range(3 if others else 0):
            driver.execute_script("window.glassdb.choose(arguments[0], arguments[1])", others[0], products[k % len(products)])
            switches.append(driver.execute_script(
                "return window.glassdb.choose(arguments[0], arguments[1])", args.id, products[k % len(products)]))
        switches.sort()
        units, unit_server = [], []
        if args.unit:
            driver.execute_script("window.glassdb.choose(arguments[0], 0)", args.id)
            driver.set_script_timeout(args.timeout)
            for k in range(args.repeat * 3):
                elements = []
                for part in args.unit.split("|"):
                    if ":" in part:
                        width, gas = part.split(":", 1)
                        elements.append({"gap_mm": round(float(width) + 0.1 * k, 3), "gas": gas})
                    else:
                        elements.append({"glass": int(part)})
                done = driver.execute_async_script(
                    "const done = arguments[arguments.length - 1];"
                    "window.glassdb.buildUnit(arguments[0]).then(done, (e) => done({error: String(e)}));",
                    elements)
                if "error" in done:
                    raise SystemExit("building the unit: " + done["error"])
                units.append(done["ms"])
                unit_server.append(done["buildMs"])
            units.sort()
            unit_server.sort()
        print(json.dumps({
            "load_ms": load_ms,
            "page_ready_ms": page_ms,
            "frame_load_ms": driver.execute_script("return window.glassdb.lastFrameLoadMs()"),
            "swaps": len(swaps),
            "swap_ms_median": swaps[len(swaps) // 2],
            "swap_ms_min": swaps[0],
            "swap_ms_max": swaps[-1],
            "swap_cpu_ms": cpu_ms,
            **({"switch_ms_median": switches[len(switches) // 2]} if switches else {}),
            **({"units": len(units), "unit_ms_median": units[len(units) // 2], "unit_ms_min": units[0],
                "unit_ms_max": units[-1], "unit_server_ms_median": unit_server[len(unit_server) // 2]}
               if units else {}),
            "renderer": renderer(driver),
        }))
    finally:
        driver.quit()


def rebind(args):
    viewer = urllib.parse.urlsplit(args.url)
    evil = f"http://{args.name}:{viewer.port}/"
    driver = browser(args.gpu, [f"--host-resolver-rules=MAP {args.name} {viewer.hostname}"])
    try:
        driver.set_script_timeout(args.timeout)
        driver.get(evil)
        page_text = driver.find_element(By.TAG_NAME, "body").text
        scene_status = driver.execute_async_script(
            "const done = arguments[arguments.length - 1];"
            "fetch('/api/scene').then(r => done(r.status), e => done(String(e)));")
        post = driver.execute_async_script(
            "const done = arguments[arguments.length - 1];"
            "fetch(arguments[0] + 'api/export', {method: 'POST', mode: 'no-cors',"
            " headers: {'Content-Type': 'text/plain'}, body: JSON.stringify({glass: '', ev: 0})})"
            ".then(r => done(r.type), e => done('failed: ' + e));", args.url)
        print(json.dumps({"page": page_text, "scene_status": scene_status, "post": post,
                          "origin": driver.execute_script("return location.origin")}))
    finally:
        driver.quit()


def export(args):
    with ready_page(args) as driver:
        driver.find_element(By.ID, "export").click()
        WebDriverWait(driver, args.timeout).until(
            lambda d: d.find_element(By.ID, "status").text.startswith(("exported", "export failed")))
        print(json.dumps({"status": driver.find_element(By.ID, "status").text,
                          "errors": driver.execute_script("return window.glassdbErrors")}))


LAYOUT_JS = r"""
const done = arguments[arguments.length - 1];
(async () => {
  const results = [];
  for (const js of arguments[0]) {
    try {
      results.push(await (new Function('return (async () => {' + js + '})()'))());
    } catch (e) {
      results.push({thrown: String(e.message || e)});
    }
  }
  await new Promise((r) => requestAnimationFrame(() => requestAnimationFrame(r)));
  const box = (el) => { if (!el) return null; const r = el.getBoundingClientRect();
    return {left: r.left, top: r.top, width: r.width, height: r.height, right: r.right, bottom: r.bottom}; };
  const canvas = document.getElementById('view-canvas');
  const names = [];
  for (const list of ['products', 'glasses']) {
    const ul = document.getElementById(list);
    const edge = ul.getBoundingClientRect().right;
    for (const el of ul.querySelectorAll('li .name')) {
      const r = el.getBoundingClientRect();
      const li = el.closest('li');
      const text = el.firstChild ? el.firstChild.textContent : el.textContent;
      names.push({list, text, cut: el.scrollWidth > el.clientWidth + 1 || r.right > edge + 0.5
          || ul.scrollWidth > ul.clientWidth + 1,
        tooltip: (li.title || '').includes(text) || (el.title || '').includes(text)});
    }
  }
  const scene = window.glassdb && window.glassdb.scene;
  const c = box(canvas);
  const split = window.glassdb && window.glassdb.split ? window.glassdb.split() : null;
  let line = null;
  if (split !== null && c) {
    const x = c.left + split * c.width, y = c.top + c.height / 2;
    const el = document.elementFromPoint(x, y);
    const style = el ? getComputedStyle(el) : null;
    line = {x, element: el ? (el.id || el.tagName) : null, background: style ? style.backgroundColor : null,
      visible: !!el && el !== canvas && style.visibility !== 'hidden' && Number(style.opacity) > 0,
      box: box(document.getElementById('split-line'))};
  }
  return {window: [window.innerWidth, window.innerHeight], stage: box(document.getElementById('stage')),
    canvas: c, frame: scene ? [scene.width, scene.height] : null, names, split_line: line,
    split_box: box(document.getElementById('split-line')), results,
    products_text: [...document.querySelectorAll('#products li')].map((li) => li.innerText),
    unit_status: document.getElementById('unit-status') ? document.getElementById('unit-status').innerText : null,
    zoom: window.glassdb && window.glassdb.zoom ? window.glassdb.zoom() : null,
    errors: window.glassdbErrors || []};
})().then(done, (e) => done({error: String(e)}));
"""


def layout(args):
    extra = [f"--window-size={args.window.replace('x', ',')}"] if args.window else []
    with ready_page(args, extra) as driver:
        driver.set_script_timeout(args.timeout)
        report = driver.execute_async_script(LAYOUT_JS, args.run)
        if args.screenshot:
            driver.save_screenshot(args.screenshot)
        print(json.dumps(report))


def build_unit(args):
    from selenium.webdriver.support.ui import Select
    with ready_page(args) as driver:
        driver.find_element(By.CSS_SELECTOR, f'#glasses li[data-id="{args.glass}"]').click()
        parts = args.panes.split("|")
        # The builder starts as pane, gap, pane; add gap + pane pairs for more panes.
        while len(driver.find_elements(By.CSS_SELECTOR, "#unit-elements > li")) < len(parts):
            driver.find_element(By.ID, "unit-add-pane").click()
        items = driver.find_elements(By.CSS_SELECTOR, "#unit-elements > li")
        pane = 0
        for item, part in zip(items, parts):
            if ":" in part:
                width, gas = part.split(":", 1)
                box = item.find_element(By.CSS_SELECTOR, "input.unit-gap")
                box.clear()
                if width != "nan":
                    box.send_keys(width)
                Select(item.find_element(By.CSS_SELECTOR, "select.unit-gas")).select_by_value(gas)
            else:
                pane += 1
                Select(item.find_element(By.CSS_SELECTOR, "select.unit-glass")).select_by_value(part)
                if pane in args.flip:
                    item.find_element(By.CSS_SELECTOR, "input.unit-flip").click()
        before = drawn(driver)
        driver.find_element(By.ID, "unit-build").click()
        WebDriverWait(driver, args.timeout).until(
            lambda d: d.find_element(By.ID, "unit-status").text not in ("", "building…"))
        said = driver.find_element(By.ID, "unit-status").text
        if args.out:
            pixels = base64.b64decode(driver.execute_script("return window.glassdb.readPixels()"))
            with open(args.out, "wb") as f:
                f.write(pixels)
        print(json.dumps({
            "status": said,
            "status_class": driver.find_element(By.ID, "unit-status").get_attribute("class"),
            "unit": driver.execute_script("return window.glassdb.lastUnit()"),
            "drawn": drawn(driver) - before,
            "products": driver.execute_script("return window.glassdbProducts()"),
            "errors": driver.execute_script("return window.glassdbErrors"),
            "renderer": renderer(driver),
        }))


def main():
    ap = argparse.ArgumentParser()
    sub = ap.add_subparsers(dest="cmd", required=True)
    c = sub.add_parser("check")
    c.add_argument("url")
    c.add_argument("--swap", action="append", default=[])
    c.add_argument("--out")
    b = sub.add_parser("bench")
    b.add_argument("url")
    b.add_argument("--id", type=int, required=True)
    b.add_argument("--products", required=True, help="product names separated by |")
    b.add_argument("--repeat", type=int, default=5)
    b.add_argument("--unit", help="also time units built on the page: 'P1|GAP_MM:GAS|P2' (catalog ids)")
    r = sub.add_parser("rebind")
    r.add_argument("url")
    r.add_argument("--name", required=True)
    e = sub.add_parser("export")
    e.add_argument("url")
    un = sub.add_parser("unit")
    un.add_argument("url")
    un.add_argument("--glass", type=int, required=True)
    un.add_argument("--panes", required=True)
    un.add_argument("--flip", type=int, action="append", default=[])
    un.add_argument("--out")
    lay = sub.add_parser("layout")
    lay.add_argument("url")
    lay.add_argument("--run", action="append", default=[], help="JS to run (awaited) before measuring")
    lay.add_argument("--window", help="window size WxH (default 1400x1000)")
    lay.add_argument("--screenshot", help="also save the window as this PNG")
    for p in (c, b, r, e, lay, un):
        p.add_argument("--timeout", type=float, default=60)
        p.add_argument("--gpu", action="store_true", help="use the machine's GPU, not SwiftShader")
    args = ap.parse_args()
    {"check": check, "bench": bench, "rebind": rebind, "export": export,
     "layout": layout, "unit": build_unit}[args.cmd](args)


if __name__ == "__main__":
    sys.exit(main())
