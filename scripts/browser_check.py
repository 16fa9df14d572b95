#!/usr/bin/env python3
"""Opens HTML pages in headless Chromium and checks what a reader would see.

For each page (loaded from disk as a file:// URL):
- the page renders: its screenshot (the first 1280 x 900 pixels) is a PNG larger than the
  screenshot of a blank page taken in the same browser;
- no console errors: no uncaught exception, no console.error / console.assert, no error logged by
  the browser (a resource that failed to load is one);
- no network: the page requests nothing but file:, data: and about: URLs;
- every relative link (a[href], link[href]) and image source (img[src], script[src]) resolves
  to an existing file or folder, and every in-page anchor (#id) to an element with that id;
- the tables work: a click on a header sorts the rows (a column of numbers ascending, an arrow on
  the header) and a second click reverses them, and a table of more than 20 rows has a filter box
  that hides the rows without its text, says how many are shown, and shows them all when cleared.

Chromium runs with the flags a closed network needs and a fresh profile, and is driven through
the DevTools protocol over a pipe (--remote-debugging-pipe: no port, no extra Python package).
Prints one line per problem (`page: what`) and exits 1 when there is any, 2 when Chromium cannot
be started. `--self-test` first checks that the checker catches a planted script error, broken
link, broken image, missing anchor, network request and blank page, and the report's table script
(read from harness/src/output/html/explore.rs) with its sort or its filter broken, and passes a
good page and a table with the working script.

Usage: python3 scripts/browser_check.py [--chromium PATH] [--screenshots DIR] [--self-test] PAGE...
"""

from __future__ import annotations

import argparse
import base64
import fcntl
import json
import os
import select
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from urllib.parse import unquote, urlsplit

FLAGS = [
    "--headless",
    "--no-sandbox",
    "--disable-gpu",
    "--disable-quic",
    "--no-first-run",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
    "--hide-scrollbars",
    "--remote-debugging-pipe",
]
VIEWPORT = (1280, 900)
TIMEOUT = 60.0
# What the page lists for the link check: [kind, raw attribute value] of every reference.
REFERENCES_JS = """JSON.stringify([].concat(
  [...document.querySelectorAll('a[href]')].map(e => ['link', e.getAttribute('href')]),
  [...document.querySelectorAll('link[href]')].map(e => ['link', e.getAttribute('href')]),
  [...document.querySelectorAll('img[src]')].map(e => ['image', e.getAttribute('src')]),
  [...document.querySelectorAll('script[src]')].map(e => ['script', e.getAttribute('src')]),
  [...document.querySelectorAll('[id]')].map(e => ['id', e.id])))"""

# Every table with a header row: a click on the first header over a column of at least two distinct
# values must sort it (a column of plain numbers ascending) with an arrow on the header, and a
# second click must reverse it; a table of more than FILTER_ROWS rows must have a filter box above
# it that, given a cell's text, hides the rows without it and counts the rows shown, and shows every
# row again when cleared. Returns the problems and how many tables were sorted and filtered.
FILTER_ROWS = 20
TABLES_JS = """(() => {
  const problems = []; let sorted = 0, filtered = 0;
  const rowsOf = t => [...t.tBodies[0].rows];
  const column = (t, i) => rowsOf(t).map(r => r.cells[i] ? r.cells[i].textContent.trim() : '');
  const tables = [...document.querySelectorAll('table')].filter(t => t.tHead && t.tHead.rows.length && t.tBodies.length);
  tables.forEach((t, n) => {
    const ths = [...t.tHead.rows[0].cells];
    const name = 'table ' + (n + 1) + ' (' + ths.slice(0, 3).map(h => h.textContent.trim()).join(', ') + ')';
    const rows = rowsOf(t).length;
    const i = ths.findIndex((h, i) => new Set(column(t, i).filter(v => v !== '' && v !== '-')).size > 1);
    if (i >= 0) {
      const head = '"' + ths[i].textContent.trim() + '"';
      ths[i].click();
      const once = column(t, i);
      const arrow = getComputedStyle(ths[i], '::after').content;
      ths[i].click();
      const twice = column(t, i);
      if (once.join('\\n') === twice.join('\\n')) problems.push(name + ': a second click on ' + head + ' did not reverse the rows');
      if (!/[\\u25b2\\u25bc]/.test(arrow)) problems.push(name + ': no arrow on the sorted header ' + head);
      const nums = once.map(v => /^-?\\d+(\\.\\d+)?(e[-+]?\\d+)?$/i.test(v) ? Number(v) : NaN);
      if (nums.every(x => !isNaN(x)) && nums.some((x, k) => k > 0 && x < nums[k - 1]))
        problems.push(name + ': a click on ' + head + ' did not sort its numbers ascending: ' + once.slice(0, 5).join(', '));
      sorted++;
    }
    if (rows > """ + str(FILTER_ROWS) + """) {
      const at = t.parentElement.classList.contains('scroll') ? t.parentElement : t;
      const box = at.previousElementSibling, input = box && box.querySelector('input');
      if (!input) { problems.push(name + ': ' + rows + ' rows and no filter box above it'); return; }
      const lower = r => r.textContent.toLowerCase();
      let q = null;
      for (const r of rowsOf(t)) for (const c of r.cells) {
        const w = c.textContent.trim().toLowerCase();
        if (q === null && w && rowsOf(t).some(x => !lower(x).includes(w))) q = w;
      }
      if (q === null) return;
      input.value = q; input.dispatchEvent(new Event('input'));
      const shown = rowsOf(t).filter(r => !r.hidden && getComputedStyle(r).display !== 'none').length;
      const want = rowsOf(t).filter(r => lower(r).includes(q)).length;
      if (shown !== want) problems.push(name + ': filtering on "' + q + '" shows ' + shown + ' rows, ' + want + ' contain it');
      if (!box.textContent.includes(shown + ' of ' + rows + ' rows')) problems.push(name + ': the filter box does not say "' + shown + ' of ' + rows + ' rows": ' + box.textContent);
      input.value = ''; input.dispatchEvent(new Event('input'));
      if (rowsOf(t).some(r => r.hidden)) problems.push(name + ': clearing the filter did not show every row');
      filtered++;
    }
  });
  return JSON.stringify({problems: problems, sorted: sorted, filtered: filtered});
})()"""


class BrowserError(Exception):
    """Chromium could not be started or stopped answering."""


class Browser:
    """One headless Chromium driven over the DevTools pipe (fd 3: commands in, fd 4: replies out)."""

    def __init__(self, chromium: str):
        self.profile = tempfile.mkdtemp(prefix="browser-check-profile-")
        to_chrome_r, self.to_chrome = os.pipe()
        self.from_chrome, from_chrome_w = os.pipe()

        def wire() -> None:  # in the child: the pipes become fds 3 and 4 (via fds above 10)
            a = fcntl.fcntl(to_chrome_r, fcntl.F_DUPFD, 10)
            b = fcntl.fcntl(from_chrome_w, fcntl.F_DUPFD, 10)
            os.dup2(a, 3)
            os.dup2(b, 4)

        self.log = tempfile.TemporaryFile()
        args = [chromium, *FLAGS, f"--user-data-dir={self.profile}", "about:blank"]
        try:
            self.proc = subprocess.Popen(
                args, preexec_fn=wire, close_fds=False, stdin=subprocess.DEVNULL, stdout=self.log, stderr=self.log
            )
        except OSError as e:
            raise BrowserError(f"cannot start {chromium}: {e}") from e
        finally:
            os.close(to_chrome_r)
            os.close(from_chrome_w)
        self.buffer = b""
        self.next_id = 0
        self.events: list[dict] = []

    def send(self, method: str, params: dict | None = None, session: str | None = None) -> int:
        self.next_id += 1
        message = {"id": self.next_id, "method": method, "params": params or {}}
        if session:
            message["sessionId"] = session
        try:
            os.write(self.to_chrome, json.dumps(message).encode() + b"\0")
        except OSError as e:
            raise BrowserError(f"Chromium is not running ({e}); its output:\n{self.output()}") from e
        return self.next_id

    def receive(self, timeout: float) -> dict:
        deadline = time.monotonic() + timeout
        while b"\0" not in self.buffer:
            ready, _, _ = select.select([self.from_chrome], [], [], max(0.0, deadline - time.monotonic()))
            if not ready:
                raise TimeoutError
            chunk = os.read(self.from_chrome, 1 << 20)
            if not chunk:
                raise BrowserError(f"Chromium closed the pipe; its output:\n{self.output()}")
            self.buffer += chunk
        message, self.buffer = self.buffer.split(b"\0", 1)
        return json.loads(message)

    def call(self, method: str, params: dict | None = None, session: str | None = None) -> dict:
        wanted = self.send(method, params, session)
        deadline = time.monotonic() + TIMEOUT
        while True:
            try:
                message = self.receive(deadline - time.monotonic())
            except TimeoutError:
                raise BrowserError(f"no answer to {method} within {TIMEOUT:.0f} s") from None
            if message.get("id") == wanted:
                if "error" in message:
                    raise BrowserError(f"{method}: {message['error']}")
                return message.get("result", {})
            self.events.append(message)

    def wait_for(self, method: str, session: str) -> None:
        deadline = time.monotonic() + TIMEOUT
        while not any(e.get("method") == method and e.get("sessionId") == session for e in self.events):
            try:
                self.events.append(self.receive(deadline - time.monotonic()))
            except TimeoutError:
                raise BrowserError(f"no {method} within {TIMEOUT:.0f} s") from None

    def drain(self, quiet: float) -> None:
        """Collects the events that arrive until none has for `quiet` seconds."""
        while True:
            try:
                self.events.append(self.receive(quiet))
            except TimeoutError:
                return

    def output(self) -> str:
        self.log.seek(0)
        return self.log.read().decode(errors="replace")[-3000:]

    def close(self) -> None:
        try:
            self.send("Browser.close")
            self.proc.wait(timeout=10)
        except (BrowserError, subprocess.TimeoutExpired):
            self.proc.kill()
            self.proc.wait()
        for fd in (self.to_chrome, self.from_chrome):
            try:
                os.close(fd)
            except OSError:
                pass
        shutil.rmtree(self.profile, ignore_errors=True)


def open_tab(browser: Browser) -> str:
    target = browser.call("Target.createTarget", {"url": "about:blank"})["targetId"]
    session = browser.call("Target.attachToTarget", {"targetId": target, "flatten": True})["sessionId"]
    for domain in ("Page", "Runtime", "Log", "Network"):
        browser.call(f"{domain}.enable", None, session)
    width, height = VIEWPORT
    metrics = {"width": width, "height": height, "deviceScaleFactor": 1, "mobile": False}
    browser.call("Emulation.setDeviceMetricsOverride", metrics, session)
    return session


def load(browser: Browser, url: str) -> tuple[str, bytes]:
    """Loads `url` in a fresh tab; returns the tab's session and its screenshot."""
    session = open_tab(browser)
    browser.events = [e for e in browser.events if e.get("sessionId") != session]
    browser.call("Page.navigate", {"url": url}, session)
    browser.wait_for("Page.loadEventFired", session)
    browser.drain(0.5)
    shot = browser.call("Page.captureScreenshot", {"format": "png"}, session)
    return session, base64.b64decode(shot["data"])


def console_errors(events: list[dict], session: str) -> list[str]:
    out = []
    for e in events:
        if e.get("sessionId") != session:
            continue
        method, p = e.get("method"), e.get("params", {})
        if method == "Runtime.exceptionThrown":
            d = p.get("exceptionDetails", {})
            text = d.get("exception", {}).get("description") or d.get("text", "exception")
            out.append(f"uncaught exception: {text.splitlines()[0]} (line {d.get('lineNumber', 0) + 1})")
        elif method == "Runtime.consoleAPICalled" and p.get("type") in ("error", "assert"):
            args = " ".join(str(a.get("value", a.get("description", ""))) for a in p.get("args", []))
            out.append(f"console.{p['type']}: {args}")
        elif method == "Log.entryAdded" and p.get("entry", {}).get("level") == "error":
            entry = p["entry"]
            out.append(f"console error: {entry.get('text', '')} {entry.get('url', '')}".strip())
        elif method == "Network.requestWillBeSent":
            request = p.get("request", {}).get("url", "")
            if urlsplit(request).scheme not in ("file", "data", "about", "blob"):
                out.append(f"network request: {request}")
    return out


def reference_problems(browser: Browser, session: str, page: Path) -> list[str]:
    result = browser.call("Runtime.evaluate", {"expression": REFERENCES_JS, "returnByValue": True}, session)
    refs = json.loads(result["result"]["value"])
    ids = {v for kind, v in refs if kind == "id"}
    out = []
    for kind, value in refs:
        if kind == "id":
            continue
        parts = urlsplit(value)
        if parts.scheme in ("data", "about", "blob"):
            continue
        if parts.scheme or parts.netloc:
            out.append(f"{kind} to another site: {value}")
            continue
        if not parts.path:
            if parts.fragment and unquote(parts.fragment) not in ids:
                out.append(f"anchor #{parts.fragment} has no element with that id")
            continue
        target = (page.parent / unquote(parts.path)).resolve()
        if not target.exists():
            out.append(f"{kind} {value} does not resolve ({target} is missing)")
    return out


TABLES_CHECKED = {"sorted": 0, "filtered": 0}


def table_problems(browser: Browser, session: str) -> list[str]:
    result = browser.call("Runtime.evaluate", {"expression": TABLES_JS, "returnByValue": True}, session)
    if "exceptionDetails" in result:
        return [f"the table check failed: {result['exceptionDetails'].get('text', 'exception')}"]
    found = json.loads(result["result"]["value"])
    TABLES_CHECKED["sorted"] += found["sorted"]
    TABLES_CHECKED["filtered"] += found["filtered"]
    return found["problems"]


def check(browser: Browser, pages: list[Path], screenshots: Path | None) -> list[str]:
    blank_session, blank = load(browser, "about:blank")
    problems = []
    for page in pages:
        page = page.resolve()
        if not page.is_file():
            problems.append(f"{page}: no such page")
            continue
        session, shot = load(browser, page.as_uri())
        what = [f"console: {m}" for m in console_errors(browser.events, session)]
        what += reference_problems(browser, session, page)
        what += table_problems(browser, session)
        if len(shot) <= len(blank) * 2:
            what.append(f"the screenshot ({len(shot)} bytes) is no larger than twice a blank page's ({len(blank)} bytes)")
        if screenshots:
            screenshots.mkdir(parents=True, exist_ok=True)
            name = "_".join(page.parts[-2:]).replace(".html", ".png")
            (screenshots / name).write_bytes(shot)
        problems += [f"{page}: {w}" for w in what]
    return problems


def report_table_script() -> tuple[str, str]:
    """The report's table script and its style, as the Rust source holds them
    (harness/src/output/html/explore.rs)."""
    source = (Path(__file__).resolve().parent.parent / "harness/src/output/html/explore.rs").read_text()

    def constant(name: str) -> str:
        start = source.index(f'const {name}: &str = r#"') + len(f'const {name}: &str = r#"')
        return source[start : source.index('"#;', start)]

    return constant("SOURCE").replace("@ROWS@", str(FILTER_ROWS)), constant("STYLE")


def self_test(chromium: str) -> int:
    """The checker must flag each planted fault and pass a good page."""
    with tempfile.TemporaryDirectory() as tmp:
        d = Path(tmp)
        (d / "dot.svg").write_text('<svg xmlns="http://www.w3.org/2000/svg" width="8" height="8"><rect width="8" height="8" fill="#c33"/></svg>')
        body = "<h1 id='top'>A page</h1><p>" + "Some text. " * 200 + "</p>"
        (d / "good.html").write_text(f"<!DOCTYPE html><html><body>{body}<img src='dot.svg'><a href='#top'>up</a> <a href='dot.svg'>svg</a></body></html>")
        bad = (
            f"<!DOCTYPE html><html><body>{body}<a href='missing.html'>gone</a><img src='nope.png'>"
            "<a href='#nowhere'>x</a><img src='http://example.invalid/x.png'>"
            "<script>undefinedFunction();</script></body></html>"
        )
        (d / "bad.html").write_text(bad)
        (d / "blank.html").write_text("<!DOCTYPE html><html><body></body></html>")
        script, style = report_table_script()
        broken = {"broken sort": ("body.appendChild(x[2])", "void x"), "broken filter": ("r.hidden = !keep", "void keep")}
        for what, (part, replacement) in broken.items():
            if part not in script:
                print(f"browser_check self-test: the report's table script has no {part!r} to break for the {what}")
                return 1
        table = "<table><thead><tr><th>name</th><th>value</th></tr></thead><tbody>" + "".join(
            f"<tr><td>row {k}</td><td class='num'>{(k * 7) % 25 + 0.5}</td></tr>" for k in range(25)
        ) + "</tbody></table>"
        for name, text in [("tables", script), *((what, script.replace(*b)) for what, b in broken.items())]:
            page = f"<!DOCTYPE html><html><head><style>{style}</style></head><body>{body}<div class='scroll'>{table}</div><script>{text}</script></body></html>"
            (d / f"{name.replace(' ', '-')}.html").write_text(page)
        browser = Browser(chromium)
        try:
            good = check(browser, [d / "good.html", d / "tables.html"], None)
            bad_found = check(browser, [d / "bad.html"], None)
            blank_found = check(browser, [d / "blank.html"], None)
            sort_found = check(browser, [d / "broken-sort.html"], None)
            filter_found = check(browser, [d / "broken-filter.html"], None)
        finally:
            browser.close()
    expected = {
        "script error": "uncaught exception",
        "broken link": "link missing.html does not resolve",
        "broken image": "image nope.png does not resolve",
        "failed load logged": "console error: Failed to load resource",
        "missing anchor": "anchor #nowhere",
        "network request": "network request: http://example.invalid",
    }
    failures = [f"the good page was flagged: {p}" for p in good]
    failures += [f"missed the planted {what}" for what, needle in expected.items() if not any(needle in p for p in bad_found)]
    if not any("screenshot" in p for p in blank_found):
        failures.append("missed the blank page")
    if not any("did not reverse the rows" in p or "did not sort" in p for p in sort_found):
        failures.append(f"missed the broken sort (found: {sort_found})")
    if not any("filtering on" in p for p in filter_found):
        failures.append(f"missed the broken filter (found: {filter_found})")
    for f in failures:
        print(f"browser_check self-test: {f}")
    if failures:
        print("browser_check self-test: what was found on the bad page:\n  " + "\n  ".join(bad_found))
        return 1
    print(
        f"browser_check self-test: ok ({len(expected)} planted faults, a blank page, a broken table sort and a broken "
        "filter caught; the good pages passed)"
    )
    return 0


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("pages", nargs="*", type=Path)
    ap.add_argument("--chromium", default=os.environ.get("CHROMIUM", "/usr/bin/chromium"))
    ap.add_argument("--screenshots", type=Path, help="save each page's screenshot here")
    ap.add_argument("--self-test", action="store_true")
    args = ap.parse_args()
    if not (shutil.which(args.chromium) or Path(args.chromium).is_file()):
        print(f"browser_check: {args.chromium} not found (apt-get install chromium)", file=sys.stderr)
        return 2
    try:
        if args.self_test and self_test(args.chromium):
            return 1
        if not args.pages:
            return 0
        TABLES_CHECKED.update(sorted=0, filtered=0)
        browser = Browser(args.chromium)
        try:
            problems = check(browser, args.pages, args.screenshots)
        finally:
            browser.close()
    except BrowserError as e:
        print(f"browser_check: {e}", file=sys.stderr)
        return 2
    for p in problems:
        print(p)
    if problems:
        return 1
    print(
        f"browser_check: {len(args.pages)} pages render with no console error, no network and no broken link; "
        f"{TABLES_CHECKED['sorted']} tables sort and {TABLES_CHECKED['filtered']} filter"
    )
    return 0


if __name__ == "__main__":
    sys.exit(main())
