"""Errors that stop a command: the CLI turns them into exit code 2 and one line on stderr."""


class ToolError(Exception):
    """The tool could not do its job (bad usage, unreadable file, missing dependency)."""


def require(module: str, extra: str):
    """Import an optional heavy dependency or raise a ToolError naming the pip extra."""
    import importlib

    try:
        return importlib.import_module(module)
    except ImportError as exc:
        raise ToolError(
            f"this command needs the '{module}' module: pip install 'urdftool[{extra}]' ({exc})"
        ) from None
