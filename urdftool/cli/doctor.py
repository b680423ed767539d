"""`urdftool doctor`: what this machine gives urdftool: the optional libraries and the layers
of the --untrusted sandbox that hold here (it starts one sandboxed reader to find out)."""

from __future__ import annotations

import json

import click

from urdftool.cli import format_option


@click.command("doctor")
@format_option("text", "json")
def command(fmt):
    """Say which optional libraries are installed and which sandbox layers are active."""
    import platform
    import sys
    from importlib.util import find_spec

    from urdftool import __version__, sandbox

    libraries = {name: find_spec(module) is not None for name, module in
                 (("trimesh", "trimesh"), ("scipy", "scipy"), ("pycollada", "collada"),
                  ("pillow", "PIL"), ("pinocchio", "pinocchio"), ("sympy", "sympy"),
                  ("pybullet", "pybullet"), ("pygls", "pygls"), ("lsprotocol", "lsprotocol"), ("mujoco", "mujoco"),
                  ("landlock", "landlock"), ("pyseccomp", "pyseccomp"))}
    layers = sandbox.layers()
    if fmt == "json":
        click.echo(json.dumps({"version": __version__, "python": sys.version.split()[0],
                               "kernel": platform.release(), "libraries": libraries,
                               "sandbox": layers}, indent=2))
        return
    click.echo(f"urdftool {__version__}, Python {sys.version.split()[0]}, "
               f"{platform.system()} {platform.release()}")
    extras = {"trimesh": "mesh", "scipy": "mesh", "pycollada": "mesh", "pillow": "mesh",
              "pinocchio": "kinematics", "sympy": "kinematics", "pybullet": "sim",
              "pygls": "lsp", "lsprotocol": "lsp", "mujoco": "mjcf"}
    for name, present in libraries.items():
        if present or name not in extras:
            click.echo(f"  {name:<12} {'installed' if present else 'missing'}")
        else:  # how to add it to this installation (errors.install_line)
            from urdftool.errors import install_line

            click.echo(f"  {name:<12} missing: {install_line(extras[name])}")
    click.echo("--untrusted sandbox (the reader of xacro, YAML, SDF and meshes):")
    for layer, state in layers.items():
        click.echo(f"  {layer:<16} {state}")
