"""The SDFormat pose graph: every link, joint, frame and nested model placed in the top model's
frame, at the zero joint configuration.

Names are looked up in the scope where they were written (``__model__``, sibling names, and
``nested::name`` into nested models). Defaults follow the spec: a link or nested model is
relative to its model frame, a joint to its child, a frame to the frame it is attached to.
A nested model's ``placement_frame`` is honoured. Cycles and missing frames are reported once
and the pose falls back to the element's default frame.
"""

from __future__ import annotations

from dataclasses import dataclass

from urdftool.sdf.reader import Entity, Reader, Scope
from urdftool.sdf.transforms import IDENTITY, Transform

WORLD = "<world>"  # the world frame (never a name: a link may be called "world")


@dataclass
class Node:
    key: str
    scope: Scope  # the scope whose names its pose refers to
    entity: Entity | None = None  # None for a model frame
    model: Scope | None = None  # set for a model frame


class PoseGraph:
    def __init__(self, top: Scope, reader: Reader):
        self.top = top
        self.reader = reader
        self.nodes: dict[str, Node] = {}
        self._memo: dict[tuple[str, str], Transform] = {}
        self._stack: list[tuple[str, str]] = []
        self._reported: set[int] = set()
        dropped: set[int] = set()  # models left out for their name: nothing of them is added
        for scope in top.walk():
            if scope.parent is not None and id(scope.parent) in dropped:
                dropped.add(id(scope))
                continue
            if scope.parent is not None and \
                    not self._add(Node(scope.frame_key, scope.parent, model=scope), scope.element):
                dropped.add(id(scope))  # one finding for the model, none for what it holds
                continue
            for entity in scope.links + scope.joints + scope.frames:
                self._add(Node(entity.key, scope, entity=entity), entity.element)

    def _add(self, node: Node, element) -> bool:
        """Add ``node``; False (and one finding) when its name is taken."""
        if node.key in self.nodes:
            other = self.nodes[node.key]
            other_element = other.entity.element if other.entity else other.model.element
            scope = node.scope if node.model is None else node.model
            included = node.model.include_element if node.model is not None else None
            if included is not None:
                self._included_twice(node, other, included)
                return False
            self.reader.report(
                "sdf.duplicate-name",
                f"name '{node.key}' is used twice in one model (also at line "
                f"{other_element.sourceline}): libsdformat refuses the model (Gazebo does not "
                "load it); the second is left out here", element,
                hint="links, joints, frames and nested models of one model need distinct names"
                + ("" if scope.version >= (1, 7) else
                   " (below SDFormat 1.7 only a link, a joint and a frame may share one)"))
            return False
        self.nodes[node.key] = node
        return True

    def _included_twice(self, node: Node, other: Node, include) -> None:
        """A model an ``<include>`` brings in under a name its model already has (the same
        model included twice without ``<name>``): said at the includer's ``<include>``, where
        the fix is written, never inside the included file (which is fine)."""
        name = node.model.name
        where = other.model.include_element if other.model is not None else None
        if where is None:
            where = other.entity.element if other.entity is not None else other.model.element
        here, there = self.reader.loc(include), self.reader.loc(where)
        also = f"line {there.line}" if there.path == here.path else f"{there.path}:{there.line}"
        taken = {key.rsplit("::", 1)[-1] for key in self.nodes}
        number = 2
        while f"{name}_{number}" in taken:
            number += 1
        written = self.reader.text_of(include, "name")
        self.reader.report(
            "sdf.duplicate-name",
            f"this <include> names its model '{name}'"
            + ("" if written else " (the included model's own name: the <include> has no <name>)")
            + f", as does the one at {also}: libsdformat refuses the model (Gazebo does not "
            "load it); this one is left out here", include,
            hint=f"give each <include> a name of its own: <name>{name}_{number}</name>")

    # -- names --------------------------------------------------------------------------------

    def lookup(self, scope: Scope, name: str) -> str | None:
        """The node key that ``name``, written in ``scope``, refers to (None if none)."""
        if name == "__model__":
            return scope.frame_key
        if scope.prefix + name in self.nodes:  # also a flattened model's 'X::__model__' frame
            return scope.prefix + name
        if name == "world":
            return WORLD
        if name.endswith("::__model__"):  # the frame of the nested model X
            key = scope.prefix + name.removesuffix("::__model__")
            node = self.nodes.get(key)
            return key if node is not None and node.model is not None else None
        return None

    @staticmethod
    def link_written(scope: Scope, name: str) -> str | None:
        """Below SDFormat 1.7 a joint's parent and child name links, by the name written, even
        where libsdformat renamed a link that shared its name with a joint or frame."""
        if scope.version >= (1, 7):
            return None
        return next((e.key for e in scope.links if e.written == name), None)

    def joint_end(self, scope: Scope, name: str) -> str | None:
        return self.link_written(scope, name) or self.lookup(scope, name)

    def _report_once(self, element, rule: str, message: str, hint: str | None = None) -> None:
        if element is None or id(element) in self._reported:
            return
        self._reported.add(id(element))
        self.reader.report(rule, message, element, hint=hint)

    def reference(self, scope: Scope, name: str, element, what: str) -> str | None:
        key = self.lookup(scope, name)
        if key is None and self.reader.is_lost(scope.prefix + name):
            return None  # in a model whose include could not be read: that finding says it
        if key is None:
            known = sorted(k[len(scope.prefix):] for k in self.nodes if k.startswith(scope.prefix))
            import difflib

            guess = [g for g in difflib.get_close_matches(name, known, n=2) if g != name]
            self._report_once(element, "sdf.missing-frame",
                              f"{what} '{name}' names no link, joint, frame or model in "
                              f"model '{scope.name}'",
                              hint=f"did you mean '{guess[0]}'?" if guess else
                              "name a link, joint, frame or nested model of this model, or __model__")
        return key

    # -- poses --------------------------------------------------------------------------------

    def default_base(self, node: Node) -> str:
        entity = node.entity
        if node.model is not None:
            return node.scope.frame_key
        if entity.kind == "joint":
            child = entity.element.findtext("child")
            key = self.joint_end(entity.scope, (child or "").strip()) if child else None
            return key if key not in (None, WORLD) else entity.scope.frame_key
        if entity.kind == "frame" and entity.attached_to:
            key = self.lookup(entity.scope, entity.attached_to)
            return key if key is not None else entity.scope.frame_key
        return entity.scope.frame_key

    def base_of(self, node: Node) -> str:
        relative_to = node.model.relative_to if node.model is not None else node.entity.relative_to
        pose_element = node.model.pose_element if node.model is not None else node.entity.pose_element
        if relative_to:
            key = self.reference(node.scope, relative_to, pose_element, "relative_to")
            if key == node.key:
                self._report_once(pose_element, "sdf.pose-cycle",
                                  f"the pose of '{node.key}' is relative to itself",
                                  hint="name another frame in relative_to")
                key = None
            if key is not None:
                return key
        return self.default_base(node)

    def pose(self, key: str, anchor: Scope | None = None) -> Transform:
        """Pose of node ``key`` in the frame of model ``anchor`` (default: the top model)."""
        anchor = anchor or self.top
        if key == anchor.frame_key:
            return IDENTITY
        if key == WORLD:
            return self.world_pose().inverse() if anchor is self.top else IDENTITY
        memo_key = (key, anchor.frame_key)
        if memo_key in self._memo:
            return self._memo[memo_key]
        node = self.nodes.get(key)
        if node is None:
            return IDENTITY
        if memo_key in self._stack:
            cycle = [k for k, _ in self._stack[self._stack.index(memo_key):]] + [key]
            element = (node.model.pose_element if node.model is not None
                       else node.entity.pose_element)
            if element is None and node.entity is not None:
                element = node.entity.element
            self._report_once(element, "sdf.pose-cycle",
                              "poses form a cycle: " + " -> ".join(cycle),
                              hint="make one of these poses relative to a frame outside the cycle")
            raise _Cycle(key)
        self._stack.append(memo_key)
        try:
            try:
                base = self.base_of(node)
                result = self.pose(base, anchor) * self._raw(node)
            except _Cycle as cycle:
                if cycle.key != key:
                    raise
                # fall back to the default frame for the node that closes the cycle
                result = self.pose(node.scope.frame_key, anchor) * self._raw(node)
        finally:
            self._stack.pop()
        self._memo[memo_key] = result
        return result

    def _raw(self, node: Node) -> Transform:
        if node.model is None:
            return node.entity.pose
        model = node.model
        raw = model.pose
        if model.placement_frame:
            key = self.reference(model, model.placement_frame, model.placement_element,
                                 "placement_frame")
            if key is not None:
                raw = raw * self.pose(key, model).inverse()
        return raw

    def world_pose(self) -> Transform:
        """Pose of the top model frame in the world (its <pose>, placement frame included)."""
        top = self.top
        raw = top.pose
        if top.placement_frame:
            key = self.reference(top, top.placement_frame, top.placement_element,
                                 "placement_frame")
            if key is not None:
                raw = raw * self.pose(key).inverse()
        return raw

    # -- attachment ---------------------------------------------------------------------------

    def attached_link(self, key: str, seen: frozenset = frozenset()) -> str | None:
        """The link key a frame, joint, link or model frame is rigidly attached to."""
        if key == WORLD:
            return WORLD
        node = self.nodes.get(key)
        if node is None or key in seen:
            if node is not None:
                element = node.entity.element if node.entity else node.model.element
                self._report_once(element, "sdf.pose-cycle",
                                  f"frames attached to each other in a cycle through '{key}'",
                                  hint="attach one of them to a link")
            return None
        seen = seen | {key}
        if node.model is not None:
            return self.canonical_link(node.model, seen)
        entity = node.entity
        if entity.kind == "link":
            return key
        if entity.kind == "joint":
            child = (entity.element.findtext("child") or "").strip()
            target = self.joint_end(entity.scope, child) if child else None
            return self.attached_link(target, seen) if target else None
        attached = entity.attached_to
        if not attached:
            return self.canonical_link(entity.scope, seen)
        target = self.reference(entity.scope, attached, entity.element, "attached_to")
        return self.attached_link(target, seen) if target else None

    def canonical_link(self, scope: Scope, seen: frozenset = frozenset()) -> str | None:
        if scope.canonical_link:
            key = self.reference(scope, scope.canonical_link, scope.element, "canonical_link")
            if key is not None:
                return self.attached_link(key, seen)
        if scope.links:
            return scope.links[0].key
        for model in scope.models:
            link = self.canonical_link(model, seen)
            if link is not None:
                return link
        return None


class _Cycle(Exception):
    def __init__(self, key: str):
        super().__init__(key)
        self.key = key
