"""urdftool: a validator and toolchain for robot descriptions (URDF, xacro, SDF)."""

__version__ = "0.1.0"
