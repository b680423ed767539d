"""Latency of ``urdftool lsp`` while typing: the server started as an editor starts it (stdio),
a real arm description opened, then edits sent one at a time, as a person types, each timed
from its ``didChange`` to the ``publishDiagnostics`` of the edited file for that version (the
server says the version its diagnostics are for). Prints the first
check's time and p50/p95/max over the edits.

    python benchmarks/bench_lsp.py [PACKAGE_DIR] [--edits N] [--interval S]

Default PACKAGE_DIR: Universal_Robots_ROS2_Description from ../shared/realworld-dev, copied
to a temporary directory with its large meshes restored from a mirror of the repository when
one is given (``--mirror GIT_DIR``; ``fetch github:UniversalRobots/Universal_Robots_ROS2_Description``
makes one) and an urdftool.toml naming ur.urdf.xacro's arguments (name:=ur ur_type:=ur5e), as
its MANIFEST entry does. Edits alternate between the entry (an argument's default) and the
macro file it includes (a joint origin in the macro body): both re-expand the arm.
"""

from __future__ import annotations

import argparse
import asyncio
import os
import re
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from lsprotocol import types as lsp
from pygls.lsp.client import LanguageClient

ROOT = Path(__file__).resolve().parent.parent
CORPUS = ROOT.parent / "shared" / "realworld-dev"
UR = "UniversalRobots+Universal_Robots_ROS2_Description"


def summary(seconds: list[float]) -> str:
    ms = sorted(v * 1000 for v in seconds)
    p95 = ms[min(len(ms) - 1, round(0.95 * (len(ms) - 1)))]
    return f"p50 {statistics.median(ms):.0f} ms, p95 {p95:.0f} ms, max {ms[-1]:.0f} ms"


def cpu_seconds(pid: int | None) -> float | None:
    """User + system CPU seconds of a process and its living descendants (the sandboxed
    reader), from Linux's /proc; None elsewhere."""
    if pid is None:
        return None
    total, todo, seen = 0.0, [pid], set()
    while todo:
        current = todo.pop()
        if current in seen:
            continue
        seen.add(current)
        try:
            fields = Path(f"/proc/{current}/stat").read_text().rsplit(")", 1)[1].split()
            total += (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")
            for task in Path(f"/proc/{current}/task").iterdir():
                todo.extend(int(c) for c in (task / "children").read_text().split())
        except (OSError, IndexError, ValueError):
            if current == pid:
                return None
    return total


def prepare(mirror: str | None) -> Path:
    """The UR description in a temporary directory, meshes restored when ``mirror`` is a git
    directory of the upstream repository."""
    corpus = CORPUS if CORPUS.is_dir() else ROOT.parent.parent / "shared" / "realworld-dev"
    target = Path(tempfile.mkdtemp(prefix="bench-lsp-")) / "ur_description"
    shutil.copytree(corpus / "src" / UR, target)
    for dirpath, _, files in os.walk(target):
        os.chmod(dirpath, 0o755)
        for name in files:
            os.chmod(os.path.join(dirpath, name), 0o644)
    restored = 0
    if mirror:
        for row in (corpus / "LARGE_FILES.txt").read_text(encoding="utf-8").splitlines():
            parts = row.split()
            if len(parts) != 4 or parts[0] != UR:
                continue
            _, commit, path, _ = parts
            dest = target / path
            dest.parent.mkdir(parents=True, exist_ok=True)
            done = subprocess.run(["git", "--git-dir", mirror, "show", f"{commit}:{path}"],
                                  capture_output=True, check=False)
            if done.returncode == 0:
                dest.write_bytes(done.stdout)
                restored += 1
    (target / "urdftool.toml").write_text(
        '[[entries]]\nfile = "urdf/ur.urdf.xacro"\nargs = { name = "ur", ur_type = "ur5e" }\n',
        encoding="utf-8")
    print(f"package: {target} ({restored} large meshes restored"
          + ("" if restored else ": mesh rules see the corpus's missing files") + ")")
    return target


async def run(package: Path, edits: int, interval: float, trusted: bool) -> None:
    client = LanguageClient("bench-lsp", "1")
    published: dict[str, list[tuple[float, int | None]]] = {}  # uri -> (time, version)
    arrived = asyncio.Event()

    @client.feature(lsp.TEXT_DOCUMENT_PUBLISH_DIAGNOSTICS)
    def on_diagnostics(params: lsp.PublishDiagnosticsParams):
        published.setdefault(params.uri, []).append((time.perf_counter(), params.version))
        arrived.set()

    @client.feature(lsp.WINDOW_LOG_MESSAGE)
    def on_log(params):
        pass

    await client.start_io(sys.executable, "-m", "urdftool", "lsp",
                          env={**os.environ, "PYTHONPATH": str(ROOT)})
    await client.initialize_async(lsp.InitializeParams(
        capabilities=lsp.ClientCapabilities(), initialization_options={"trusted": trusted}))
    client.initialized(lsp.InitializedParams())
    entry = package / "urdf" / "ur.urdf.xacro"
    macro = package / "urdf" / "ur_macro.xacro"
    texts = {p: p.read_text(encoding="utf-8") for p in (entry, macro)}
    uris = {p: p.resolve().as_uri() for p in texts}

    async def wait_for(uri: str, since: float, version: int = 1) -> float:
        """Seconds from ``since`` to the first diagnostics of ``uri`` for the text of
        ``version`` or later (when the server says the version; else the first after)."""
        while True:
            times = [t for t, v in published.get(uri, []) if t > since and (v is None or
                                                                             v >= version)]
            if times:
                return times[0] - since
            arrived.clear()
            await asyncio.wait_for(arrived.wait(), 120)

    start = time.perf_counter()
    for path in (entry, macro):
        client.text_document_did_open(lsp.DidOpenTextDocumentParams(
            lsp.TextDocumentItem(uris[path], "xml", 1, texts[path])))
    first = await wait_for(uris[entry], start)
    await wait_for(uris[macro], start)
    count = sum(1 for u in published)
    print(f"first check (open, cold in this process): {first * 1000:.0f} ms, "
          f"{count} file(s) published")
    # what changes: an argument default in the entry, a joint origin in the macro body
    argument = re.search(r'(<xacro:arg name="safety_k_position" default=")([^"]*)"',
                         texts[entry])
    origin = re.search(r'(<origin xyz="0 0 )([^"]*)(" rpy="0 0 0"\s*/>)', texts[macro])
    assert argument and origin, "the UR files changed: pick other edit places"
    latencies, cpu, cycles = [], [], []  # cycles: CPU from one edit to the next
    pid = client._server.pid if getattr(client, "_server", None) is not None else None
    versions = {p: 1 for p in texts}
    used = None
    for index in range(edits):
        path = entry if index % 2 == 0 else macro
        found = argument if path is entry else origin
        # (never the text already there: 21.. differs from the default 20, origins from 0)
        value = f"{21 + index}" if path is entry else f"{index * 0.001:g}"
        text = texts[path][:found.start(2)] + value + texts[path][found.end(2):]
        versions[path] += 1
        await asyncio.sleep(interval)
        before, used = used, cpu_seconds(pid)
        if before is not None and used is not None:
            cycles.append(used - before)
        sent = time.perf_counter()
        client.text_document_did_change(lsp.DidChangeTextDocumentParams(
            lsp.VersionedTextDocumentIdentifier(version=versions[path], uri=uris[path]),
            [lsp.TextDocumentContentChangeWholeDocument(text=text)]))
        latencies.append(await wait_for(uris[path], sent, versions[path]))
        if used is not None:
            cpu.append(cpu_seconds(pid) - used)
    mode = "trusted" if trusted else "untrusted: sandboxed reader"
    print(f"change -> diagnostics over {len(latencies)} edits (interval "
          f"{interval * 1000:.0f} ms, {mode}): {summary(latencies)}")
    if cpu:
        print(f"server CPU per edit (its sandboxed reader's too; independent of the load): "
              f"{summary(cpu)}; entry edits {summary(cpu[0::2])}, macro-body edits "
              f"{summary(cpu[1::2])}")
        print(f"server CPU per edit cycle (from an edit to the next: the work after the "
              f"diagnostics too, its garbage collection): {summary(cycles)}")
    load = os.getloadavg()[0] if hasattr(os, "getloadavg") else float("nan")
    print(f"load average during the run: {load:.1f} on {os.cpu_count()} CPUs")
    await client.shutdown_async(None)
    client.exit(None)
    await client.stop()


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("package", nargs="?", help="a package directory laid out as the UR "
                        "description (default: a copy of the corpus's)")
    parser.add_argument("--mirror", help="git directory of the upstream repository (meshes)")
    parser.add_argument("--edits", type=int, default=40)
    parser.add_argument("--interval", type=float, default=0.3,
                        help="seconds between the diagnostics of an edit and the next edit")
    parser.add_argument("--untrusted", action="store_true",
                        help="the default of an editor that says nothing of trust")
    options = parser.parse_args()
    package = Path(options.package) if options.package else prepare(options.mirror)
    asyncio.run(run(package, options.edits, options.interval, not options.untrusted))


if __name__ == "__main__":
    main()
