"""A small headless-Chromium driver over the DevTools protocol (the project's `websockets` test dependency):
open a page, wait for it to load, evaluate JavaScript and take a screenshot. Enough to look at the docs as a
reader would, without a browser-automation package."""

from __future__ import annotations

import asyncio
import base64
import itertools
import json
import shutil
import subprocess
import tempfile
import time
import urllib.request
from pathlib import Path
from typing import Any

import websockets

FLAGS = ("--headless", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
         "--disable-background-networking", "--disable-component-update", "--disable-sync",
         "--hide-scrollbars", "--window-size=1280,1600")


def find_chromium() -> str | None:
    return next((p for name in ("chromium", "chromium-browser", "google-chrome") if (p := shutil.which(name))), None)


class Browser:
    """``with Browser() as b: b.look(url, png)`` -> what the page's images did (``loaded``, ``broken``)."""

    def __init__(self, executable: str | None = None):
        self.executable = executable or find_chromium()
        if self.executable is None:
            raise FileNotFoundError("no chromium on this machine")

    def __enter__(self) -> Browser:
        self._profile = tempfile.TemporaryDirectory()
        self._proc = subprocess.Popen([self.executable, *FLAGS, "--remote-debugging-port=0",
                                       f"--user-data-dir={self._profile.name}", "about:blank"],
                                      stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        port_file = Path(self._profile.name) / "DevToolsActivePort"
        deadline = time.monotonic() + 30
        while not port_file.exists() or len(port_file.read_text().splitlines()) < 2:
            if time.monotonic() > deadline or self._proc.poll() is not None:
                raise RuntimeError("chromium did not start")
            time.sleep(0.1)
        port = port_file.read_text().splitlines()[0]
        self._pages = f"http://127.0.0.1:{port}/json"
        return self

    def __exit__(self, *exc: Any) -> None:
        self._proc.terminate()
        try:
            self._proc.wait(timeout=10)
        except subprocess.TimeoutExpired:
            self._proc.kill()
        self._profile.cleanup()

    def look(self, url: str, screenshot: Path | None = None) -> dict[str, Any]:
        return asyncio.run(self._look(url, screenshot))

    async def _look(self, url: str, screenshot: Path | None) -> dict[str, Any]:
        with urllib.request.urlopen(self._pages, timeout=10) as resp:
            targets = json.loads(resp.read())
        ws_url = next(t["webSocketDebuggerUrl"] for t in targets if t.get("type") == "page")
        ids = itertools.count(1)
        async with websockets.connect(ws_url, max_size=None) as ws:

            async def call(method: str, **params: Any) -> dict[str, Any]:
                n = next(ids)
                await ws.send(json.dumps({"id": n, "method": method, "params": params}))
                while True:
                    msg = json.loads(await ws.recv())
                    if msg.get("id") == n:
                        return msg.get("result", {})

            await call("Page.enable")
            await call("Page.navigate", url=url)
            for _ in range(200):  # until the document and its images have loaded
                state = await call("Runtime.evaluate", expression="document.readyState", returnByValue=True)
                if state["result"].get("value") == "complete":
                    break
                await asyncio.sleep(0.05)
            check = ("JSON.stringify([...document.images].map(i => ({src: i.getAttribute('src'), "
                     "ok: i.complete && i.naturalWidth > 0})))")
            found = await call("Runtime.evaluate", expression=check, returnByValue=True)
            images = json.loads(found["result"]["value"])
            named = await call("Runtime.evaluate", expression="document.title", returnByValue=True)
            title = named["result"]["value"]
            if screenshot is not None:
                shot = await call("Page.captureScreenshot", format="png")
                screenshot.write_bytes(base64.b64decode(shot["data"]))
        return {"title": title, "loaded": [i["src"] for i in images if i["ok"]],
                "broken": [i["src"] for i in images if not i["ok"]]}
