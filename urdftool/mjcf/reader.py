"""Reading MJCF (issue 32): the file and everything it names checked against the run's roots
BEFORE MuJoCo sees it (MuJoCo would read any path it is given), then compiled by MuJoCo itself,
so that defaults, classes and includes mean what MuJoCo makes of them.

- ``is_mjcf(text)``: a ``<mujoco>`` document.
- ``referenced(path, roots)``: every file the model names (``<include file>``, followed, and
  every ``file*`` attribute: meshes, textures, height fields, skins, models), resolved as MuJoCo
  resolves them (the main file's directory, ``meshdir``/``texturedir``/``assetdir``), each
  inside the roots and a regular file within the size limit; a ``MjcfRefused`` otherwise,
  located at the element. Bounded: ``MAX_INCLUDE_DEPTH`` deep, ``MAX_FILES`` files.
- ``compile_model(path, roots)``: ``mujoco.MjModel`` of the checked file, with the locations
  of its named bodies and joints (``(tag, name) -> Loc``).
"""

from __future__ import annotations

import os
import stat
from pathlib import Path

from urdftool.errors import ToolError, require
from urdftool.files import MAX_BYTES, read_regular
from urdftool.findings import Loc

MAX_INCLUDE_DEPTH = 20
MAX_FILES = 5000
_DIRS = ("meshdir", "texturedir", "assetdir")
_MESH_TAGS = ("mesh", "skin", "hfield")


class MjcfRefused(ToolError):
    """A file the MJCF names is outside the roots, missing where required, or too large."""


def is_mjcf(text: str) -> bool:
    head = text.lstrip()[:4096]
    while head.startswith(("<?", "<!--")):
        end = head.find("?>" if head.startswith("<?") else "-->")
        if end < 0:
            return False
        head = head[end + (2 if head.startswith("<?") else 3):].lstrip()
    return head.startswith("<mujoco") and (len(head) == 7 or not head[7].isalnum())


def _parse(path: Path, data: bytes):
    from lxml import etree

    from urdftool.xmlrepair import secure_parser

    try:
        return etree.fromstring(data, secure_parser(), base_url=str(path))
    except etree.XMLSyntaxError as exc:
        line = exc.position[0] if exc.position else None
        raise ToolError(f"{path}:{line or ''}: not well-formed XML: {exc.msg}") from None


class _Reading:
    def __init__(self, main: Path, roots):
        self.main = main
        self.top = main.resolve().parent
        self.roots = roots
        self.files: list[str] = [str(main)]
        self.locs: dict[tuple[str, str], Loc] = {}
        self.dirs: dict[str, str] = {}

    def check(self, element, attribute: str, spec: str, where: Path) -> Path:
        """The file ``spec`` names, refused when outside the roots or not a regular file."""
        line = element.sourceline
        target = Path(spec) if os.path.isabs(spec) else self.top / spec
        if not self.roots.readable(target):
            raise MjcfRefused(f"{where}:{line}: <{element.tag} {attribute}=\"{spec}\"> is outside "
                              "the repository and the operator's directories (-P NAME=DIR); "
                              "not read")
        if len(self.files) >= MAX_FILES:
            raise MjcfRefused(f"{where}:{line}: more than {MAX_FILES} files named (urdftool's "
                              "limit); not read")
        try:
            info = os.stat(target)
        except OSError:
            return target  # MuJoCo says it is missing, with its own message
        if not stat.S_ISREG(info.st_mode) or info.st_size > MAX_BYTES:
            raise MjcfRefused(f"{where}:{line}: {spec} is not a regular file of at most "
                              f"{MAX_BYTES >> 20} MB; not read")
        self.files.append(str(target))
        return target

    def walk(self, root, where: Path, depth: int) -> None:
        for element in root.iter():
            if not isinstance(element.tag, str):
                continue
            tag = element.tag
            if tag == "compiler":
                for key in _DIRS:
                    if element.get(key) is not None:
                        self.dirs[key] = element.get(key)
            name = element.get("name")
            if name is not None and tag in ("body", "joint", "geom", "site"):
                self.locs.setdefault((tag, name), Loc(str(where), element.sourceline or 0, 1))
            if tag == "include" and element.get("file") is not None:
                if depth >= MAX_INCLUDE_DEPTH:
                    raise MjcfRefused(f"{where}:{element.sourceline}: includes more than "
                                      f"{MAX_INCLUDE_DEPTH} deep (urdftool's limit); not read")
                target = self.check(element, "file", element.get("file"), where)
                try:
                    data = read_regular(target)
                except OSError as exc:
                    raise ToolError(f"{where}:{element.sourceline}: <include file="
                                    f"\"{element.get('file')}\">: {exc.strerror or exc}") from None
                self.walk(_parse(target, data), target, depth + 1)

    def assets(self, root, where: Path) -> None:
        """Every file attribute of the assets, resolved with the compiler's directories."""
        for element in root.iter():
            if not isinstance(element.tag, str) or element.tag in ("include",):
                continue
            for attribute, spec in element.attrib.items():
                if not attribute.startswith("file") or not spec:
                    continue
                if element.tag in _MESH_TAGS:
                    folder = self.dirs.get("meshdir", self.dirs.get("assetdir"))
                elif element.tag == "texture":
                    folder = self.dirs.get("texturedir", self.dirs.get("assetdir"))
                else:
                    folder = None
                self.check(element, attribute,
                           spec if folder is None or os.path.isabs(spec)
                           else os.path.join(folder, spec), where)


def referenced(path: Path, roots) -> tuple[list[str], dict[tuple[str, str], Loc]]:
    """(every file the model names, resolved and checked; locations of named elements)."""
    reading = _Reading(path, roots)
    try:
        data = read_regular(path)
    except OSError as exc:
        raise ToolError(f"{path}: {exc.strerror or exc}") from None
    root = _parse(path, data)
    reading.walk(root, path, 0)
    # a second pass, now that every <compiler> directory is known (MuJoCo applies them to the
    # whole model, wherever they are written)
    reading.assets(root, path)
    for include in list(reading.files[1:]):
        if include.endswith(".xml"):
            try:
                reading.assets(_parse(Path(include), read_regular(include)), Path(include))
            except OSError:
                continue
    return reading.files, reading.locs


WARNINGS: list[str] = []  # what MuJoCo warned while compiling (never its MUJOCO_LOG.TXT)


def compiled(mujoco, path: Path | None = None, text: str | None = None):
    """``MjModel.from_xml_path`` (or ``from_xml_string``) with MuJoCo's warnings kept in
    ``WARNINGS``: its default handler prints them and appends them to MUJOCO_LOG.TXT in the
    current directory, a file no urdftool command may write."""
    previous = mujoco.get_mju_user_warning()
    mujoco.set_mju_user_warning(lambda message: WARNINGS.append(" ".join(str(message).split())))
    try:
        if path is not None:
            return mujoco.MjModel.from_xml_path(str(path))
        return mujoco.MjModel.from_xml_string(text)
    finally:
        mujoco.set_mju_user_warning(previous)


def compile_model(path: Path, roots):
    """(mujoco.MjModel, files read, locations) of a checked MJCF file. A model MuJoCo refuses
    is a ToolError with MuJoCo's own message."""
    mujoco = require("mujoco", "mjcf")
    files, locs = referenced(path, roots)
    try:
        model = compiled(mujoco, path)
    except (ValueError, RuntimeError) as exc:
        message = " ".join(str(exc).split())
        raise ToolError(f"{path}: MuJoCo cannot load it: {message}") from None
    return model, files, locs
