"""Errors that stop a command: the CLI turns them into exit code 2 and one line on stderr."""


class ToolError(Exception):
    """The tool could not do its job (bad usage, unreadable file, missing dependency)."""


class NothingToCheck(ToolError):
    """No robot file among the paths given (``check`` says so and exits 0)."""


def exception_text(exc: BaseException) -> str:
    """``Type: message`` of an exception from a library, one line, its type named once: some
    libraries' messages already start with it (pycollada's ``DaeMalformedError.__str__`` gives
    "DaeMalformedError: ..."), which the plain f-string doubled."""
    name = type(exc).__name__
    lines = [line.strip() for line in str(exc).strip().splitlines() if line.strip()]
    if not lines:
        return name
    return lines[0] if lines[0].startswith(name) else f"{name}: {lines[0]}"


def require(module: str, extra: str):
    """Import an optional heavy dependency or raise a ToolError naming the pip extra."""
    import importlib

    try:
        return importlib.import_module(module)
    except ImportError as exc:
        raise ToolError(
            f"this command needs the '{module}' module: {install_line(extra)} ({exc})"
        ) from None


def install_line(extra: str) -> str:
    """The command that adds the optional dependencies ``extra`` to THIS installation of
    urdftool, into the Python running it: a source checkout is installed from its folder
    (``pip install -e 'DIR[extra]'``), an installation from a folder, archive or repository
    from where it came (PEP 610's direct_url.json); with no record, the README's line from a clone (urdftool is
    on no package index: an index name could install someone else's package)."""
    import shlex
    import sys
    from pathlib import Path

    root = Path(__file__).resolve().parent.parent
    try:
        project = (root / "pyproject.toml").read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError):
        project = ""
    checkout = root if 'name = "urdftool"' in project else None
    direct = None
    if checkout is None:
        import json
        from importlib import metadata

        try:
            direct = json.loads(metadata.distribution("urdftool").read_text("direct_url.json")
                                or "null")
        except (metadata.PackageNotFoundError, ValueError, OSError):
            direct = None
    return pip_line(f"{shlex.quote(sys.executable or 'python')} -m pip install", extra,
                    checkout, direct)


def pip_line(pip: str, extra: str, checkout, direct) -> str:
    """``install_line`` from what it found: the source checkout's folder, or the
    direct_url.json record (a dict, None when installed from an index)."""
    import shlex
    from urllib.parse import unquote, urlparse

    if checkout is not None:
        return f"{pip} -e {shlex.quote(f'{checkout}[{extra}]')}"
    if not isinstance(direct, dict) or not isinstance(direct.get("url"), str):
        # no record of where it came from: urdftool is on no package index (a name there would
        # be someone else's package), so the README's line, from a clone
        return (f"{pip} {shlex.quote(f'./urdftool[{extra}]')} (from the folder holding your "
                f"clone of urdftool: it is on no package index)")
    url = direct["url"]
    dir_info, vcs = direct.get("dir_info"), direct.get("vcs_info")
    if isinstance(dir_info, dict) and url.startswith("file://"):
        folder = unquote(urlparse(url).path)
        editable = "-e " if dir_info.get("editable") is True else ""
        return f"{pip} {editable}{shlex.quote(f'{folder}[{extra}]')}"
    if isinstance(vcs, dict) and isinstance(vcs.get("vcs"), str):
        revision = vcs.get("commit_id")
        url = f"{vcs['vcs']}+{url}" + (f"@{revision}" if isinstance(revision, str) else "")
    return f"{pip} {shlex.quote(f'urdftool[{extra}] @ {url}')}"
