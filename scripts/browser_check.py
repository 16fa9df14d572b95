#!/usr/bin/env python3
"""Opens HTML pages in headless Chromium and checks what a reader would see.

For each page (loaded from disk as a file:// URL):
- the page renders: its screenshot (the first 1280 x 900 pixels) is a PNG larger than the
  screenshot of a blank page taken in the same browser;
- no console errors: no uncaught exception, no console.error / console.assert, no error logged by
  the browser (a resource that failed to load is one);
- no network: the page requests nothing but file:, data: and about: URLs;
- every relative link (a[href], link[href]) and image source (img[src], script[src]) resolves
  to an existing file or folder, and every in-page anchor (#id) to an element with that id.

Chromium runs with the flags a closed network needs and a fresh profile, and is driven through
the DevTools protocol over a pipe (--remote-debugging-pipe: no port, no extra Python package).
Prints one line per problem (`page: what`) and exits 1 when there is any, 2 when Chromium cannot
be started. `--self-test` first checks that the checker catches a planted script error, broken
link, broken image, missing anchor, network request and blank page, and passes a good page.

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
        if len(shot) <= len(blank) * 2:
            what.append(f"the screenshot ({len(shot)} bytes) is no larger than twice a blank page's ({len(blank)} bytes)")
        if screenshots:
            screenshots.mkdir(parents=True, exist_ok=True)
            name = "_".join(page.parts[-2:]).replace(".html", ".png")
            (screenshots / name).write_bytes(shot)
        problems += [f"{page}: {w}" for w in what]
    return problems


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
        browser = Browser(chromium)
        try:
            good = check(browser, [d / "good.html"], None)
            bad_found = check(browser, [d / "bad.html"], None)
            blank_found = check(browser, [d / "blank.html"], None)
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
    for f in failures:
        print(f"browser_check self-test: {f}")
    if failures:
        print("browser_check self-test: what was found on the bad page:\n  " + "\n  ".join(bad_found))
        return 1
    print(f"browser_check self-test: ok ({len(expected)} planted faults and a blank page caught, the good page passed)")
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
    print(f"browser_check: {len(args.pages)} pages render with no console error, no network and no broken link")
    return 0


if __name__ == "__main__":
    sys.exit(main())
