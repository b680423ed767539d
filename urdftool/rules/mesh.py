"""Rules of the `mesh` family (see DESIGN.md for what the family covers)."""

from __future__ import annotations
