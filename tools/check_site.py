"""Open the built site in headless Chromium and check every page as a reader would see it.

    .venv/bin/python tools/check_site.py docs/_build/html

Serves the folder on a loopback port and, page by page, asserts: no console error and no
uncaught exception; every internal link (and its #anchor) resolves; every image has loaded
with a non-zero size; every equation has been typeset by MathJax without an error; and the
site's search finds each scene by name. Every demo page must show at least one figure. Writes
screenshots of the front page and of one demo page to ``<site>/../screenshots/``. Exit 1 with
one line per failure; Chromium is Debian's (``/usr/bin/chromium``, or ``CHROMIUM=``), driven
by Playwright.
"""

from __future__ import annotations

import functools
import http.server
import os
import re
import sys
import threading
from pathlib import Path
from urllib.parse import urldefrag, urljoin, urlparse

DEMO_SHOT = "_generated/demos/blister_adhesive.html"
#: MathJax typesets a page's equations after it loads; wait this long at most [ms]
TYPESET_MS = 60_000


def serve(root: Path) -> tuple[http.server.ThreadingHTTPServer, str]:
    handler = functools.partial(_Quiet, directory=str(root))
    server = http.server.ThreadingHTTPServer(("127.0.0.1", 0), handler)
    threading.Thread(target=server.serve_forever, daemon=True).start()
    return server, f"http://127.0.0.1:{server.server_address[1]}/"


class _Quiet(http.server.SimpleHTTPRequestHandler):
    def log_message(self, *args):
        pass


def pages(root: Path) -> list[str]:
    """Every HTML page of the site but Sphinx's own (search, index) and the raw sources."""
    skip = {"search.html", "genindex.html"}
    return sorted(str(p.relative_to(root)) for p in root.rglob("*.html")
                  if p.name not in skip and "_sources" not in p.parts and "_static" not in p.parts)


def anchors(root: Path, relative: str) -> set[str]:
    text = (root / relative).read_text(errors="replace")
    return set(re.findall(r'\sid="([^"]+)"', text))


def check(root: Path) -> list[str]:
    from playwright.sync_api import sync_playwright

    failures: list[str] = []
    server, base = serve(root)
    chromium = os.environ.get("CHROMIUM", "/usr/bin/chromium")
    if not Path(chromium).is_file():
        sys.exit(f"check_site: no Chromium at {chromium} (apt-get install chromium, or set CHROMIUM=)")
    try:
        with sync_playwright() as p:
            browser = p.chromium.launch(executable_path=chromium, args=["--no-sandbox"])
            page = browser.new_page(viewport={"width": 1280, "height": 900})
            errors: list[str] = []
            page.on("console", lambda m: errors.append(m.text) if m.type == "error" else None)
            page.on("pageerror", lambda e: errors.append(str(e)))
            ids: dict[str, set[str]] = {}
            for relative in pages(root):
                errors.clear()
                page.goto(base + relative, wait_until="load")
                failures += [f"{relative}: console: {e}" for e in errors]
                failures += _links(page, root, base, relative, ids)
                failures += _images(page, relative)
                failures += _equations(page, relative)
            failures += _search(page, base)
            shots = root.parent / "screenshots"
            shots.mkdir(exist_ok=True)
            for name, relative in (("front.png", "index.html"), ("demo.png", DEMO_SHOT)):
                page.goto(base + relative, wait_until="load")
                _typeset(page)
                page.screenshot(path=str(shots / name), full_page=name == "front.png")  # the gallery too
            browser.close()
    finally:
        server.shutdown()
    return failures


def _links(page, root: Path, base: str, relative: str, ids: dict[str, set[str]]) -> list[str]:
    out = []
    for href in page.eval_on_selector_all("a[href]", "els => els.map(e => e.getAttribute('href'))"):
        if urlparse(href).scheme in ("http", "https", "mailto"):
            continue
        target, fragment = urldefrag(urljoin(base + relative, href))
        path = urlparse(target).path.lstrip("/") or "index.html"
        if path.endswith("/"):
            path += "index.html"
        if not (root / path).is_file():
            out.append(f"{relative}: broken link {href}")
        elif fragment and path.endswith(".html"):
            if path not in ids:
                ids[path] = anchors(root, path)
            if fragment not in ids[path]:
                out.append(f"{relative}: no anchor #{fragment} in {path}")
    return out


def _images(page, relative: str) -> list[str]:
    page.wait_for_load_state("load")
    images = page.eval_on_selector_all(
        "img", "els => els.map(e => [e.getAttribute('src'), e.complete, e.naturalWidth, e.naturalHeight])")
    out = [f"{relative}: image {src} not shown ({w}x{h})" for src, done, w, h in images if not (done and w and h)]
    if relative.startswith("_generated/demos/") and not any(w for _, _, w, _ in images):
        out.append(f"{relative}: a demo page without a figure")
    return out


def _typeset(page) -> bool:
    try:
        page.wait_for_function(
            "() => Array.from(document.querySelectorAll('.math')).every("
            "m => m.querySelector('.MathJax, .MathJax_Display, script[type^=\"math/tex\"]'))",
            timeout=TYPESET_MS)
    except Exception:
        return False
    return True


def _equations(page, relative: str) -> list[str]:
    if not page.query_selector(".math"):
        return []
    if not _typeset(page):
        return [f"{relative}: equations not typeset in {TYPESET_MS // 1000} s"]
    bad = page.eval_on_selector_all(".MathJax_Error, merror, .merror", "els => els.map(e => e.textContent)")
    return [f"{relative}: equation error {b!r}" for b in bad]


def _search(page, base: str) -> list[str]:
    from bcfem.scenes import REGISTRY

    out = []
    for scene in REGISTRY:
        page.goto(f"{base}search.html?q={scene}", wait_until="load")
        try:
            page.wait_for_selector(f"#search-results a[href*='scenes/{scene}.html']", timeout=20_000)
        except Exception:
            out.append(f"search: {scene!r} does not find its scene page")
    return out


if __name__ == "__main__":
    site = Path(sys.argv[1] if len(sys.argv) > 1 else "docs/_build/html").resolve()
    if not (site / "index.html").is_file():
        sys.exit(f"check_site: no site in {site} (make docs builds it)")
    found = check(site)
    for line in found:
        print(line)
    print(f"check_site: {len(pages(site))} pages, {len(found)} failures; screenshots in {site.parent / 'screenshots'}")
    sys.exit(1 if found else 0)
