"""The engine behind ``urdftool lsp`` without the protocol: an edit re-runs only the checks
that read the edited file; YAML read by xacro is parsed once per text and every expansion
still gets its own data."""

from __future__ import annotations

from urdftool.lsp.engine import Engine, Settings

MACROS = """<robot xmlns:xacro="http://www.ros.org/wiki/xacro">
  <xacro:macro name="arm" params="prefix length">
    <link name="${prefix}link"/>
  </xacro:macro>
</robot>
"""
ENTRY = """<robot name="r" xmlns:xacro="http://www.ros.org/wiki/xacro">
  <xacro:include filename="macros.xacro"/>
  <xacro:property name="data" value="${xacro.load_yaml('data.yaml')}"/>
  <link name="base"/>
  <xacro:arm prefix="a_" length="${data['length']}"/>
  <joint name="j" type="fixed"><parent link="base"/><child link="a_link"/></joint>
  <link name="n${len(data['items'])}"/>
  <link name="d${int(round(data['angle'] * 1000))}"/>
  <xacro:if value="${data['items'].append(1) or True}"><link name="m${len(data['items'])}"/></xacro:if>
</robot>
"""
DATA = "length: 2\nangle: !degrees 180.0\nitems: [1, 2]\n"  # a unit tag on a literal
OTHER = '<robot name="o"><link name="x"/></robot>\n'


def _engine() -> Engine:
    settings, problems = Settings().updated({"trusted": True}, trust=True)
    assert problems == []
    return Engine(settings)



def _spy_checks(engine) -> list[str]:
    """The file names of the targets ``engine`` checks from now on, in order."""
    checked: list[str] = []
    original = engine._check_one

    def spy(unit, index, options):
        checked.append(unit.targets[index].path.rsplit("/", 1)[-1])
        original(unit, index, options)

    engine._check_one = spy
    return checked

def test_an_edit_rechecks_only_the_checks_that_read_the_file(tmp_path):
    (tmp_path / "package.xml").write_text("<package/>", encoding="utf-8")
    (tmp_path / "macros.xacro").write_text(MACROS, encoding="utf-8")
    (tmp_path / "data.yaml").write_text(DATA, encoding="utf-8")
    (tmp_path / "robot.urdf.xacro").write_text(ENTRY, encoding="utf-8")
    (tmp_path / "other.urdf").write_text(OTHER, encoding="utf-8")
    engine = _engine()
    checked = _spy_checks(engine)
    engine.refresh([str(tmp_path / "macros.xacro")])
    assert sorted(checked) == ["macros.xacro", "other.urdf", "robot.urdf.xacro"]
    checked.clear()
    engine.set_buffer(str(tmp_path / "macros.xacro"),
                      MACROS.replace("${prefix}link", "${prefix}lnk"))
    engine.refresh([str(tmp_path / "macros.xacro")])
    # the entry that reads it; the fragment's own check is put off (its findings come
    # through the entry), the URDF that does not read it is not checked again
    assert checked == ["robot.urdf.xacro"]
    result = next(iter(engine.snapshot.values()))
    found = {(d.rule, d.message) for ds in result.diagnostics.values() for d in ds}
    assert any(rule == "structure.missing-link" and "a_link" in message
               for rule, message in found), found
    assert engine.refresh_pending() and checked == ["robot.urdf.xacro", "macros.xacro"]


def test_an_open_file_no_check_reads_costs_nothing(tmp_path):
    """A YAML file opened in the editor makes no check of its own (editors send every YAML
    buffer); once an entry that loads it is checked, an unsaved edit of it re-checks the
    entry, which reads the buffer."""
    (tmp_path / "package.xml").write_text("<package/>", encoding="utf-8")
    (tmp_path / "macros.xacro").write_text(MACROS, encoding="utf-8")
    (tmp_path / "data.yaml").write_text(DATA, encoding="utf-8")
    (tmp_path / "robot.urdf.xacro").write_text(ENTRY, encoding="utf-8")
    (tmp_path / "ci.yaml").write_text("on: push\n", encoding="utf-8")
    engine = _engine()
    data = str(tmp_path / "data.yaml")
    assert engine.refresh([str(tmp_path / "ci.yaml"), data]) == [] and not engine.units
    engine.refresh([str(tmp_path / "robot.urdf.xacro")])
    engine.set_buffer(data, DATA.replace("items: [1, 2]", "items: [1, 2, 3, 4]"))
    assert engine.refresh([data])
    result = next(iter(engine.snapshot.values()))
    names = {link.name for _, robot in result.checks if robot is not None
             for link in robot.links}
    assert "n4" in names and "n2" not in names, names  # the buffer's data, not the disk's


def _two_fragments(tmp_path):
    """An entry including two macro files, both edited: both own checks are put off."""
    (tmp_path / "package.xml").write_text("<package/>", encoding="utf-8")
    second = MACROS.replace('name="arm"', 'name="leg"')
    (tmp_path / "macros.xacro").write_text(MACROS, encoding="utf-8")
    (tmp_path / "legs.xacro").write_text(second, encoding="utf-8")
    (tmp_path / "data.yaml").write_text(DATA, encoding="utf-8")
    entry = ENTRY.replace('<xacro:include filename="macros.xacro"/>',
                          '<xacro:include filename="macros.xacro"/>'
                          '<xacro:include filename="legs.xacro"/>')
    (tmp_path / "robot.urdf.xacro").write_text(entry, encoding="utf-8")
    engine = _engine()
    engine.refresh([str(tmp_path / "robot.urdf.xacro")])
    engine.set_buffer(str(tmp_path / "macros.xacro"), MACROS + "<!-- 1 -->")
    engine.set_buffer(str(tmp_path / "legs.xacro"), second + "<!-- 1 -->")
    engine.refresh([str(tmp_path / "macros.xacro"), str(tmp_path / "legs.xacro")])
    return engine, entry


def test_checks_put_off_stop_between_targets_when_asked(tmp_path):
    """A change during the checks put off stops them after the target being checked; the
    rest stays pending and runs later."""
    engine, _ = _two_fragments(tmp_path)
    assert engine.pending()
    checked = _spy_checks(engine)
    assert engine.refresh_pending(lambda: bool(checked)) and len(checked) == 1
    assert engine.pending()
    engine.refresh_pending(lambda: False)
    assert sorted(checked) == ["legs.xacro", "macros.xacro"] and not engine.pending()


def test_a_change_does_not_wait_for_the_pause_of_the_checks_put_off(tmp_path, monkeypatch):
    """The server waits PENDING_DELAY without a change before it runs the checks put off; a
    change during that wait is checked at once (it used to wait for the end of the pause)."""
    import asyncio
    import time

    from urdftool.lsp import server as server_module

    monkeypatch.setattr(server_module, "PENDING_DELAY", 60.0)
    engine, entry = _two_fragments(tmp_path)
    robot = str(tmp_path / "robot.urdf.xacro")

    async def scenario() -> float:
        server = server_module.UrdfLanguageServer(engine.settings)
        server.engine = engine
        server.frozen = True  # (no gc.freeze of the test process)
        published = asyncio.Event()
        texts = {robot: entry.replace('name="base"', 'name="base2"')}
        server.buffer = texts.get
        server.publish = lambda roots: published.set()
        server.schedule(str(tmp_path / "macros.xacro"))  # nothing new: only the pending
        # its check is published, and the server goes on to wait for a pause before this task
        # runs again (no await between the two); a fixed sleep let a slow first check publish
        # after the clear below, which ended the wait before the change was checked
        await asyncio.wait_for(published.wait(), 30)
        assert engine.pending() and not server.task.done()
        published.clear()
        start = time.monotonic()
        server.schedule(robot)
        await asyncio.wait_for(published.wait(), 30)
        took = time.monotonic() - start
        assert engine.pending()  # still put off: there was no pause
        server.task.cancel()
        server.worker.shutdown()
        return took

    assert asyncio.run(scenario()) < 30
    found = next(iter(engine.snapshot.values())).diagnostics
    assert any(d.rule == "structure.missing-link" and "'base'" in d.message
               for ds in found.values() for d in ds), found


def test_garbage_is_collected_after_a_check_unless_a_change_waits(monkeypatch):
    """The garbage of a check is collected once its diagnostics are out; while changes keep
    coming, at most COLLECT_EVERY checks apart."""
    import gc

    from urdftool.lsp import server as server_module

    collected = []
    monkeypatch.setattr(gc, "collect", lambda *a: collected.append(1) or 0)
    server = server_module.UrdfLanguageServer()
    server.frozen = True
    server.collect()
    assert len(collected) == 1
    server.changed.add("x")
    for _ in range(3 * server_module.COLLECT_EVERY):
        server.collect()
    assert len(collected) == 1 + 3


def test_yaml_data_changed_by_an_expression_is_not_shared_between_expansions(tmp_path):
    """The parsed YAML is kept between expansions (the server expands on every edit); an
    expression that changes the data it got changes only its own expansion's copy."""
    (tmp_path / "macros.xacro").write_text(MACROS, encoding="utf-8")
    (tmp_path / "data.yaml").write_text(DATA, encoding="utf-8")
    (tmp_path / "robot.urdf.xacro").write_text(ENTRY, encoding="utf-8")
    import xacro
    from lxml import etree

    from urdftool.check import CheckOptions, check_model

    names = []
    for _ in range(3):
        robot = check_model(tmp_path / "robot.urdf.xacro", CheckOptions())[1]
        names.append(sorted(link.name for link in robot.links))
    document = xacro.process_file(str(tmp_path / "robot.urdf.xacro"), mappings={})
    plain = sorted(e.get("name") for e in etree.fromstring(document.toxml().encode()).iter("link"))
    assert names == [plain] * 3 and "n2" in plain and "d3142" in plain


def _frame(message: dict) -> bytes:
    import json

    body = json.dumps(message).encode()
    return b"Content-Length: %d\r\n\r\n" % len(body) + body


def _messages(data: bytes) -> list[dict]:
    import json

    found = []
    while data:
        head, _, rest = data.partition(b"\r\n\r\n")
        length = int(head.split(b"Content-Length:")[1].split(b"\r\n")[0])
        found.append(json.loads(rest[:length]))
        data = rest[length:]
    return found


def test_the_server_answers_bad_requests_and_exits_cleanly(tmp_path):
    """Over raw stdio: requests about nothing (a missing file, a line past the end, an
    untitled buffer) answer null, a binary buffer gets diagnostics, diagnostics carry the
    version of the text they are for, and shutdown then exit end the process with status 0
    and no traceback."""
    import subprocess
    import sys

    from tests.conftest import ROOT

    robot = tmp_path / "r.urdf"
    robot.write_text("<robot name='r'><link name='a'/></robot>\n", encoding="utf-8")
    doc = robot.resolve().as_uri()
    other = tmp_path / "o.urdf"
    other.write_text(OTHER, encoding="utf-8")
    second = other.resolve().as_uri()
    nowhere = (tmp_path / "missing.urdf").resolve().as_uri()
    position = {"line": 0, "character": 3}
    requests = [
        {"jsonrpc": "2.0", "id": 1, "method": "initialize",
         "params": {"capabilities": {}, "initializationOptions": {"trusted": True}}},
        {"jsonrpc": "2.0", "method": "initialized", "params": {}},
        {"jsonrpc": "2.0", "id": 2, "method": "textDocument/hover",
         "params": {"textDocument": {"uri": nowhere}, "position": position}},
        {"jsonrpc": "2.0", "method": "textDocument/didOpen", "params": {"textDocument": {
            "uri": doc, "languageId": "xml", "version": 1, "text": "\x00\x01 not xml"}}},
        {"jsonrpc": "2.0", "method": "textDocument/didOpen", "params": {"textDocument": {
            "uri": second, "languageId": "xml", "version": 4, "text": OTHER}}},
        {"jsonrpc": "2.0", "method": "textDocument/didChange", "params": {
            "textDocument": {"uri": second, "version": 7},
            "contentChanges": [{"text": OTHER.replace('"x"/>', '"x"/><link name="y"/>')}]}},
        {"jsonrpc": "2.0", "id": 3, "method": "workspace/executeCommand",
         "params": {"command": "urdftool.check", "arguments": [doc]}},
        {"jsonrpc": "2.0", "id": 4, "method": "textDocument/definition",
         "params": {"textDocument": {"uri": doc}, "position": {"line": 99, "character": 0}}},
        {"jsonrpc": "2.0", "id": 5, "method": "textDocument/codeAction",
         "params": {"textDocument": {"uri": "untitled:Untitled-1"},
                    "range": {"start": position, "end": position},
                    "context": {"diagnostics": []}}},
    ]
    server = subprocess.Popen([sys.executable, "-m", "urdftool", "lsp"], stdin=subprocess.PIPE,
                              stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                              env={"PYTHONPATH": str(ROOT), "PATH": "/usr/bin:/bin",
                                   "URDFTOOL_CACHE_DIR": str(tmp_path / "cache")})
    try:
        server.stdin.write(b"".join(_frame(m) for m in requests))
        server.stdin.flush()
        received = []
        while {1, 2, 3, 4, 5} - {m.get("id") for m in received}:
            head = b""
            while not head.endswith(b"\r\n\r\n"):
                byte = server.stdout.read(1)
                assert byte, server.stderr.read().decode()
                head += byte
            length = int(head.split(b"Content-Length:")[1].split(b"\r\n")[0])
            received.extend(_messages(head + server.stdout.read(length)))
        rest, errors = server.communicate(
            _frame({"jsonrpc": "2.0", "id": 6, "method": "shutdown"})
            + _frame({"jsonrpc": "2.0", "method": "exit"}), timeout=60)
    finally:
        if server.poll() is None:
            server.kill()
    received.extend(_messages(rest))
    assert server.returncode == 0, errors.decode()
    assert b"Traceback" not in errors, errors.decode()
    replies = {m["id"]: m for m in received if "id" in m}
    assert sorted(replies) == [1, 2, 3, 4, 5, 6]
    assert all("error" not in reply for reply in replies.values()), replies
    assert replies[2]["result"] is None and replies[4]["result"] is None
    assert replies[5]["result"] in (None, [])
    diagnostics = [m for m in received
                   if m.get("method") == "textDocument/publishDiagnostics"
                   and m["params"]["uri"] == doc]
    assert diagnostics and diagnostics[-1]["params"]["diagnostics"], diagnostics
    # diagnostics say the version of the text they are for (the last one sent)
    last = [m["params"] for m in received if m.get("method") == "textDocument/publishDiagnostics"
            and m["params"]["uri"] == second][-1]
    assert last["version"] == 7 and any("'y'" in d["message"] for d in last["diagnostics"])


def test_settings_refuse_what_they_do_not_know():
    """A setting with an unknown key, a wrong type or an unknown rule is refused and said
    (the server logs it to the client); ``trusted`` only from the initialization options."""
    base = Settings()
    settings, problems = base.updated({"select": ["joint", "joint.no-such-rule"],
                                       "ignore": ["mesh"], "bogus": 1, "args": {"a": 1},
                                       "trusted": True, "packages": {"p": "/x"}})
    assert settings.select == [] and settings.ignore == ["mesh"] and settings.args == {}
    assert settings.packages == {"p": "/x"} and settings.trusted is False
    assert len(problems) == 4 and any("joint.no-such-rule" in p for p in problems)
    assert base.updated({"trusted": True}, trust=True)[0].trusted is True
