"""MJCF (MuJoCo) input and output: ``reader`` (checked, then compiled by MuJoCo) and ``export``
(``urdftool convert ROBOT --to mjcf``)."""
