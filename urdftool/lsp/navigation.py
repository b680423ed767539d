"""Hover, definitions, references, document symbols and completion of ``urdftool lsp``."""

from __future__ import annotations


def register(server, guarded) -> None:
    pass
