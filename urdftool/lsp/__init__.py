"""``urdftool lsp``: the language server (``server``), the checks behind it (``engine``), its
code actions (``actions``) and navigation (``navigation``). Never imported by ``check``."""
