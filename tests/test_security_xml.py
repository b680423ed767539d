"""XML attacks on every parser urdftool uses: external entities (XXE), entity expansion
("billion laughs"), parameter entities, external DTDs over the network, XInclude, deep nesting.

The parsers: ``urdftool.xmlrepair.secure_parser()`` (every file urdftool reads itself), the copy
xacro parses (``xml.dom.minidom``/expat, fed by our patched ``xacro.parse`` with the element
tree re-serialised, so no DOCTYPE ever reaches it) and the final parse of the expanded text.
"""

from __future__ import annotations

import http.server
import json
import threading

import pytest
from lxml import etree

from tests.conftest import WallLessWaiting, run_urdftool

SECRET = "TOPSECRET-4f1d"
XACRO_NS = 'xmlns:xacro="http://www.ros.org/wiki/xacro"'
BODY = '<link name="a{use}"/><link name="b">{text}</link>'


def _robot(doctype: str, use: str = "", text: str = "", xacro: bool = False, extra: str = ""):
    robot = f'<robot name="r" {XACRO_NS}>' if xacro else '<robot name="r">'
    prop = '<xacro:property name="q" value="1"/><link name="c${q}"/>' if xacro else ""
    return (f'<?xml version="1.0"?>\n{doctype}\n{robot}{prop}'
            f'{BODY.format(use=use, text=text)}{extra}</robot>\n')


def _laughs() -> str:
    lines = ['<!ENTITY lol0 "lol">']
    for level in range(1, 10):
        lines.append(f'<!ENTITY lol{level} "{f"&lol{level - 1};" * 10}">')
    return "<!DOCTYPE robot [\n" + "\n".join(lines) + "\n]>"


@pytest.fixture
def secret_file(tmp_path):
    path = tmp_path / "secret.txt"
    path.write_text(SECRET)
    return path


@pytest.fixture
def http_server():
    """A local HTTP server that records every request (nothing may reach it)."""
    hits: list[str] = []

    class Handler(http.server.BaseHTTPRequestHandler):
        def do_GET(self):
            hits.append(self.path)
            body = f'<!ENTITY leak "{SECRET}">'.encode()
            self.send_response(200)
            self.send_header("Content-Length", str(len(body)))
            self.end_headers()
            self.wfile.write(body)

        def log_message(self, *args):
            pass

    server = http.server.HTTPServer(("127.0.0.1", 0), Handler)
    thread = threading.Thread(target=server.serve_forever, daemon=True)
    thread.start()
    yield f"http://127.0.0.1:{server.server_address[1]}", hits
    server.shutdown()
    server.server_close()


def _run_all(path, *options):
    """check (json) and expand: every diagnostic and every byte of output."""
    check = run_urdftool("check", "--format", "json", *options, path)
    expand = run_urdftool("expand", *options, path)
    report = json.loads(check.out)
    diagnostics = [d for f in report["files"] for d in f["diagnostics"]]
    return check, expand, diagnostics


MODES = ["--trusted", "--untrusted"]


@pytest.mark.parametrize("xacro", [False, True], ids=["urdf", "xacro"])
@pytest.mark.parametrize("mode", MODES)
def test_external_entity_is_reported_not_read(xacro, mode, tmp_path, secret_file):
    doctype = f'<!DOCTYPE robot [<!ENTITY x SYSTEM "file://{secret_file}">]>'
    path = tmp_path / ("robot.urdf.xacro" if xacro else "robot.urdf")
    path.write_text(_robot(doctype, use="&x;", text="&x;", xacro=xacro))
    check, expand, diagnostics = _run_all(path, mode)
    assert SECRET not in check.out + check.err + expand.out + expand.err
    assert check.code == 1 and any(d["severity"] == "error" and d["rule"].startswith(("xml.",
                                                                                       "xacro."))
                                   for d in diagnostics)
    assert "Traceback" not in check.err + expand.err


@pytest.mark.parametrize("xacro", [False, True], ids=["urdf", "xacro"])
@pytest.mark.parametrize("mode", MODES)
def test_billion_laughs_is_reported_not_expanded(xacro, mode, tmp_path):
    path = tmp_path / ("robot.urdf.xacro" if xacro else "robot.urdf")
    path.write_text(_robot(_laughs(), use="&lol9;", xacro=xacro))
    with WallLessWaiting() as clock:  # wall time less the machine's other load
        check, expand, diagnostics = _run_all(path, mode)
    assert clock.seconds < 10
    assert "lollollol" not in check.out + expand.out
    assert check.code == 1 and any(d["severity"] == "error" for d in diagnostics)


@pytest.mark.parametrize("xacro", [False, True], ids=["urdf", "xacro"])
def test_no_network_for_external_dtd_or_parameter_entity(xacro, tmp_path, http_server):
    url, hits = http_server
    for number, doctype in enumerate([
            f'<!DOCTYPE robot SYSTEM "{url}/evil.dtd">',
            f'<!DOCTYPE robot PUBLIC "-//evil//EN" "{url}/public.dtd">',
            f'<!DOCTYPE robot [<!ENTITY % p SYSTEM "{url}/param.dtd"> %p;]>',
            f'<!DOCTYPE robot [<!ENTITY n SYSTEM "{url}/entity.xml">]>']):
        path = tmp_path / (f"robot{number}.urdf.xacro" if xacro else f"robot{number}.urdf")
        path.write_text(_robot(doctype, text="&n;" if "ENTITY n" in doctype else "", xacro=xacro))
        for mode in MODES:
            check, expand, diagnostics = _run_all(path, mode)
            assert SECRET not in check.out + expand.out
            if xacro:  # the xacro path refuses any DTD before xacro sees the file
                assert any("DOCTYPE" in d["message"] for d in diagnostics), diagnostics
                assert expand.code == 1 and expand.out == ""
    assert hits == []


@pytest.mark.parametrize("xacro", [False, True], ids=["urdf", "xacro"])
def test_parameter_entity_reads_no_file(xacro, tmp_path, secret_file):
    doctype = (f'<!DOCTYPE robot [<!ENTITY % p SYSTEM "file://{secret_file}"> %p;'
               f'<!ENTITY % q "<!ENTITY leak \'{SECRET}-x\'>"> %q;]>')
    path = tmp_path / ("robot.urdf.xacro" if xacro else "robot.urdf")
    path.write_text(_robot(doctype, text="&leak;", xacro=xacro))
    check, expand, diagnostics = _run_all(path, "--trusted")
    assert f"{SECRET}-x" not in check.out + expand.out  # the declared text is not substituted
    assert check.code == 1 and diagnostics


@pytest.mark.parametrize("xacro", [False, True], ids=["urdf", "xacro"])
def test_xinclude_is_not_processed(xacro, tmp_path, secret_file):
    extra = (f'<xi:include xmlns:xi="http://www.w3.org/2001/XInclude" href="{secret_file}" '
             'parse="text"/>')
    path = tmp_path / ("robot.urdf.xacro" if xacro else "robot.urdf")
    path.write_text(_robot("", xacro=xacro, extra=extra))
    for mode in MODES:
        check, expand, _ = _run_all(path, mode)
        assert SECRET not in check.out + check.err + expand.out + expand.err
        if expand.out:  # passed through as an inert element, never replaced by the file
            assert "xi:include" in expand.out or "XInclude" in expand.out


def test_secure_parser_settings():
    from urdftool.xmlrepair import secure_parser

    data = (b'<?xml version="1.0"?>\n<!DOCTYPE r [<!ENTITY x SYSTEM "file:///etc/hostname">]>\n'
            b'<r><a>&x;</a><xi:include xmlns:xi="http://www.w3.org/2001/XInclude" '
            b'href="/etc/hostname" parse="text"/></r>')
    root = etree.fromstring(data, secure_parser())
    assert isinstance(root[0][0], etree._Entity)  # left as a reference, not resolved
    assert root[0].text is None
    assert root[1].tag.endswith("include")  # XInclude only happens on .xinclude(): never called
    with pytest.raises(etree.XMLSyntaxError):  # huge_tree=False: depth is bounded
        etree.fromstring(b"<a>" * 100_000 + b"</a>" * 100_000, secure_parser())
    with pytest.raises(etree.XMLSyntaxError):
        etree.fromstring(_robot(_laughs(), use="&lol9;").encode(), secure_parser())


def test_minidom_never_sees_a_doctype(tmp_path, monkeypatch):
    """xacro's own parser (expat via minidom) gets our re-serialised element tree only."""
    import xml.dom.minidom

    seen: list[str] = []
    original = xml.dom.minidom.parseString

    def spy(data, *args, **kwargs):
        seen.append(data.decode() if isinstance(data, bytes) else data)
        return original(data, *args, **kwargs)

    monkeypatch.setattr(xml.dom.minidom, "parseString", spy)
    included = tmp_path / "part.xacro"
    included.write_text('<?xml version="1.0"?>\n<!DOCTYPE robot>\n'
                        f'<robot {XACRO_NS}><link name="part"/></robot>\n')
    path = tmp_path / "robot.urdf.xacro"
    path.write_text(f'<?xml version="1.0"?>\n<!DOCTYPE robot>\n<robot name="r" {XACRO_NS}>'
                    '<xacro:include filename="part.xacro"/><xacro:property name="q" value="1"/>'
                    '<link name="a${q}"/></robot>\n')
    result = run_urdftool("expand", "--trusted", path)
    assert result.code == 0, result.err
    # the file, its include, and expand writing the document as xacro does
    assert len(seen) == 3 and not any("<!DOCTYPE" in s or "<!ENTITY" in s for s in seen)


def test_expanded_text_cannot_smuggle_entities(tmp_path):
    """Entity-like text made by expressions is escaped on output, never expanded on re-parse."""
    path = tmp_path / "robot.urdf.xacro"
    path.write_text(f'<robot name="r" {XACRO_NS}><xacro:property name="amp" value="&amp;"/>'
                    '<link name="${amp}lol;"/><link name="b">${amp}#60;tag${amp}#62;</link>'
                    '</robot>')
    result = run_urdftool("expand", "--trusted", path)
    assert result.code == 0, result.err
    root = etree.fromstring(result.out.encode())
    assert root[0].get("name") == "&lol;" and root[1].text == "&#60;tag&#62;"
