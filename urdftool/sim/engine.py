"""One model through PyBullet: load, place, hold the home pose, step, and judge.

Runs inside a worker process (see ``runner``) with file descriptors 1 and 2 captured, so that
PyBullet's banner and warnings never reach our stdout; its messages are passed on in the load
check when it refuses a model.

The setup: DIRECT mode, gravity, ``plane.urdf`` from pybullet_data, ``URDF_USE_INERTIA_FROM_FILE``
(otherwise PyBullet recomputes inertia from the collision shapes and hides the defects we look
for), base fixed when the model is anchored, otherwise dropped from just above its lowest point,
every revolute/continuous/prismatic joint held at its home pose (zero clamped into the limits, a
mimic follower at its leader's image) by POSITION_CONTROL with the URDF's effort as the force
limit. Joint limits are checked against the URDF, not PyBullet (which drops ``lower > upper``).
"""

from __future__ import annotations

import contextlib
import math
import os
import re
import time
from itertools import combinations

from urdftool.sim import CHECKS, CheckResult, ModelResult, SimOptions
from urdftool.sim.capture import bullet_messages, captured_fds
from urdftool.sim.prepare import CONTROLLED, Prepared, describe_location, prepare

UNLIMITED_FORCE = 1e6  # a joint without an effort limit: the motor is as strong as needed
DROP_GAP = 0.005  # m between the lowest point and the ground when a free model is released
ANCHOR_GAP = 0.001  # m: an anchored model reaching below the ground is lifted this far above it
GRAVITY = 9.81
ROBOT_GROUP = 64  # collision filter group of the robot's links (Bullet uses 1..32 itself)


def _check(name: str, status: str, message: str, **values) -> CheckResult:
    return CheckResult(f"sim.{name}", status, message, values)


def _skip_rest(result: ModelResult, reason: str) -> None:
    done = {c.check for c in result.checks}
    for name in CHECKS:
        if f"sim.{name}" not in done:
            result.checks.append(_check(name, "skip", reason))
    order = {f"sim.{name}": i for i, name in enumerate(CHECKS)}
    result.checks.sort(key=lambda c: order.get(c.check, len(order)))


def _joined_messages(text: str) -> list[str]:
    """PyBullet prints one message in pieces ("...for Link:", "arm"; "No inertial data for
    link, ...", "imu_link"): join a piece that ends with ':' or a lone name to the one before."""
    merged: list[str] = []
    for line in bullet_messages(text):
        if merged and (merged[-1].endswith(":") or (" " not in line and "." not in line)):
            merged[-1] += (" " if merged[-1].endswith(":") else ": ") + line
        else:
            merged.append(line)
    return merged


def run_model(path: str, options: SimOptions, from_directory: bool = False,
              picture: str | None = None) -> ModelResult:
    """Simulate one model and judge it; with ``picture``, write the pictures of it at rest there
    (and beside it, ``-collision.png``). Raises ToolError only if the file cannot be read."""
    started, cpu = time.perf_counter(), time.process_time()
    result = ModelResult(path=str(path))
    prepared = prepare(path, options, from_directory)
    result.robot = prepared.robot
    result.notes.extend(prepared.notes)
    result.timing["prepare"] = time.perf_counter() - started
    try:
        if prepared.problem:
            result.checks.append(_check("load", "fail", f"cannot load: {prepared.problem}"))
            _skip_rest(result, "the model did not load")
            return result
        if prepared.kinematics_only:
            # what check says of it (inertia.kinematics-only): no simulator can use it as is
            _skip_rest(result, "not simulated: no link has an <inertial> (kinematics only, as "
                               "`urdftool check` says: inertia.kinematics-only)")
            return result
        result.anchored, result.anchor_reason = prepared.anchored, prepared.anchor_reason
        with captured_fds() as printed:
            run = _Run(prepared, options, result, picture)
            try:
                run.execute()
            except Exception as exc:
                if type(exc).__module__ != "pybullet":
                    raise
                # PyBullet refused something after loading the model (a query on a body it
                # built wrong): the model cannot be simulated; say so and go on with the rest
                result.checks = [c for c in result.checks if c.check != "sim.load"]
                result.checks.insert(0, _check("load", "fail", "PyBullet failed on this model "
                                               f"after loading it: {exc}"))
                _skip_rest(result, "PyBullet failed")
            finally:
                run.close()
        messages = list(dict.fromkeys(describe_location(prepared, m)
                                      for m in _joined_messages(printed.text)))
        load = result.check("load")
        if run.load_error is None and load is not None:
            changed = [m for m in messages if "setting inertia to zero" in m or "unsupported" in m]
            if changed:
                load.values["pybullet_warnings"] = changed
                load.message += "; PyBullet changed the model: " + "; ".join(changed[:4]) + (
                    f" and {len(changed) - 4} more" if len(changed) > 4 else "")
        if run.load_error is not None:
            detail = "; ".join(m for m in messages if "No inertial data" not in m)
            message = f"PyBullet: {run.load_error}" + (f" ({detail})" if detail else "")
            if prepared.xml_problem:
                message += f"; the XML is not well-formed: {prepared.xml_problem}"
            if prepared.unresolved:
                message += ("; unresolved meshes: " + ", ".join(prepared.unresolved[:5]) +
                            " (give packages with -P NAME=DIR)")
            result.checks.insert(0, _check("load", "fail", message))
            _skip_rest(result, "the model did not load")
        return result
    finally:
        prepared.cleanup()
        result.timing["total"] = time.perf_counter() - started
        result.timing["cpu"] = time.process_time() - cpu


class _Run:
    """The PyBullet session of one model."""

    def __init__(self, prepared: Prepared, options: SimOptions, result: ModelResult,
                 picture: str | None = None):
        self.prepared, self.options, self.result = prepared, options, result
        self.picture = picture
        # PyBullet answers closest-point queries between two links of one body only when the
        # body was loaded with self-collision (and then only for non-adjacent links). The
        # model is loaded that way and self-collision is switched off again with collision
        # groups before stepping; a model with collision groups of its own in the URDF is
        # instead asked through a second copy of it (twice the load time)
        self.twin_query = bool(re.search(r"<collision\b[^<>]*\b(group|mask)\s*=",
                                         prepared.urdf_text))
        self.limits = options.thresholds
        self.load_error: str | None = None
        self.client = None

    def close(self) -> None:
        if self.client is not None:
            with contextlib.suppress(Exception):  # already gone
                self.client.disconnect()
            self.client = None

    # -- setting up ----------------------------------------------------------------------------

    def execute(self) -> None:
        import pybullet
        import pybullet_data
        from pybullet_utils.bullet_client import BulletClient

        prepared, result = self.prepared, self.result
        self.client = p = BulletClient(connection_mode=pybullet.DIRECT)
        p.setGravity(0, 0, -GRAVITY)
        p.setTimeStep(1.0 / self.options.rate)
        self.plane = p.loadURDF(os.path.join(pybullet_data.getDataPath(), "plane.urdf"))
        started = time.perf_counter()
        try:
            flags = pybullet.URDF_USE_INERTIA_FROM_FILE | (
                0 if self.picture else pybullet.URDF_IGNORE_VISUAL_SHAPES)
            if not self.twin_query:  # so that PyBullet answers pair queries within the body
                flags |= (pybullet.URDF_USE_SELF_COLLISION |
                          pybullet.URDF_USE_SELF_COLLISION_INCLUDE_PARENT)
            body = p.loadURDF(prepared.urdf_file, [0, 0, 0], [0, 0, 0, 1],
                              useFixedBase=prepared.anchored, flags=flags)
        except pybullet.error as exc:
            self.load_error = str(exc).strip() or "cannot load the URDF"
            result.timing["load"] = time.perf_counter() - started
            return
        result.timing["load"] = time.perf_counter() - started
        try:
            p.getBasePositionAndOrientation(body)
        except pybullet.error:
            self.load_error = "PyBullet returned a broken body"
            return
        self.body = body
        self.link_names = {-1: p.getBodyInfo(body)[0].decode("utf-8", "replace")}
        self.joint_index: dict[str, int] = {}
        for index in range(p.getNumJoints(body)):
            info = p.getJointInfo(body, index)
            self.joint_index[info[1].decode("utf-8", "replace")] = index
            self.link_names[index] = info[12].decode("utf-8", "replace")
        result.links, result.joints = len(self.link_names), len(self.joint_index)
        load_message = f"loaded {len(self.link_names)} links, {len(self.joint_index)} joints"
        if prepared.unresolved:
            load_message += " (unresolved meshes left out: " + ", ".join(prepared.unresolved[:5]) + ")"
        result.checks.append(_check("load", "pass", load_message, load_s=result.timing["load"],
                                    links=len(self.link_names), joints=len(self.joint_index)))

        self.controlled = [(self.joint_index[name], fact) for name, fact in prepared.joints.items()
                           if fact.type in CONTROLLED and name in self.joint_index]
        for index, fact in self.controlled:
            p.resetJointState(body, index, fact.home)
        checks_started = time.perf_counter()
        self.collision_links = [i for i in self.link_names if p.getCollisionShapeData(body, i)]
        result.checks.append(self._mass())
        result.checks.append(self._self_collision())
        self._place()
        checks_time = time.perf_counter() - checks_started
        if self.controlled:
            p.setJointMotorControlArray(
                body, [i for i, _ in self.controlled], pybullet.POSITION_CONTROL,
                targetPositions=[f.home for _, f in self.controlled],
                forces=[max(f.effort, 0.0) if f.effort is not None else UNLIMITED_FORCE
                        for _, f in self.controlled])
        self._step()
        started = time.perf_counter()
        self._judge()
        result.timing["checks"] = checks_time + time.perf_counter() - started
        if self.picture and self.nan_at is None:
            from urdftool.sim.render import render_model

            started = time.perf_counter()
            result.images = render_model(self, self.picture)
            result.timing["render"] = time.perf_counter() - started
        elif self.picture:
            result.notes.append("no picture: the state became NaN")

    def _mass(self) -> CheckResult:
        p, prepared = self.client, self.prepared
        simulated = {name: p.getDynamicsInfo(self.body, i)[0] for i, name in self.link_names.items()}
        self.masses = {i: p.getDynamicsInfo(self.body, i)[0] for i in self.link_names}
        declared = dict(prepared.masses)
        dropped = [name for name in declared if name not in simulated]
        base = self.link_names[-1]
        # with the base fixed, its body (the links welded to it) never moves: its mass is moot
        still = {name for name in declared if prepared.anchored and (
            name == base or prepared.group.get(name, -1) == prepared.group.get(base, -2))}
        defaulted = [name for name, mass in declared.items()
                     if mass is None and name in simulated and name not in still]
        mismatched = []
        for name, mass in declared.items():
            if name not in simulated or (prepared.anchored and name == base):
                continue
            expected = 1.0 if mass is None else mass  # PyBullet's mass for a link w/o inertial
            if abs(simulated[name] - expected) > self.limits.mass_tolerance * max(1.0, abs(expected)):
                mismatched.append((name, expected, simulated[name]))
        urdf_total = sum(m for name, m in declared.items() if m is not None
                         and not (prepared.anchored and name == base))
        bullet_total = sum(m for name, m in simulated.items()
                           if not (prepared.anchored and name == base))
        values = {"urdf_kg": urdf_total, "pybullet_kg": bullet_total, "dropped": dropped,
                      "default_mass_links": defaulted,
                      "mismatched": [{"link": n, "urdf_kg": e, "pybullet_kg": s}
                                  for n, e, s in mismatched]}
        where = " (base fixed, not counted)" if prepared.anchored else ""
        if dropped or mismatched or defaulted:
            parts = []
            if dropped:
                parts.append("PyBullet dropped link(s) " + ", ".join(f"'{n}'" for n in dropped[:8]))
            if defaulted:  # the URDF says no mass (spec: zero), PyBullet simulates 1 kg each
                parts.append(f"{len(defaulted)} link(s) without <inertial> get PyBullet's default "
                             "1 kg (" + ", ".join(f"'{n}'" for n in defaulted[:5])
                             + ("..." if len(defaulted) > 5 else "") + "): give each an "
                             "<inertial> (a massless frame: mass 0 and zero inertia)")
            parts.extend(f"link '{n}': URDF {e:g} kg, PyBullet {s:g} kg"
                         for n, e, s in mismatched[:8])
            return _check("mass", "fail", f"total {bullet_total:g} kg in PyBullet vs {urdf_total:g} "
                          f"kg in the URDF{where}: " + "; ".join(parts), **values)
        return _check("mass", "pass", f"{bullet_total:g} kg in PyBullet, as declared{where}",
                      **values)

    def _allowed(self, a: str, b: str) -> bool:
        return frozenset((a, b)) in self.prepared.srdf_pairs or any(
            {a, b} == {x, y} for x, y in self.options.allow_collision)

    def _self_collision(self) -> CheckResult:
        p, prepared, strict = self.client, self.prepared, self.options.strict_collision
        known = set(self.link_names.values())
        unknown = sorted({n for pair in self.options.allow_collision for n in pair} - known)
        if unknown:
            self.result.notes.append("--allow-collision names no link of this model: " +
                                     ", ".join(unknown))
        boxes = {i: p.getAABB(self.body, i) for i in self.collision_links}
        failing, ancestral, looped = [], [], []
        import pybullet

        other = self.body
        if self.twin_query:  # loaded exactly as the model was (nothing has moved it yet)
            other = p.loadURDF(self.prepared.urdf_file, [0, 0, 0], [0, 0, 0, 1],
                               useFixedBase=self.prepared.anchored,
                               flags=pybullet.URDF_USE_INERTIA_FROM_FILE |
                               pybullet.URDF_IGNORE_VISUAL_SHAPES)
            for index, fact in self.controlled:
                p.resetJointState(other, index, fact.home)
        for a, b in combinations(self.collision_links, 2):
            name_a, name_b = self.link_names[a], self.link_names[b]
            relation = prepared.relation(name_a, name_b)
            if relation == "adjacent" or self._allowed(name_a, name_b):
                continue
            (lo_a, hi_a), (lo_b, hi_b) = boxes[a], boxes[b]
            if any(lo_a[k] > hi_b[k] or lo_b[k] > hi_a[k] for k in range(3)):
                continue
            points = p.getClosestPoints(self.body, other, 0.0, a, b)
            if not points:
                continue
            depth = -min(point[8] for point in points)
            if depth > self.limits.collision_depth:
                if prepared.loop_cut(name_a, name_b):
                    looped.append((name_a, name_b, depth))
                else:
                    (ancestral if relation == "ancestor" and not strict else failing).append(
                        (name_a, name_b, depth))

        if self.twin_query:
            p.removeBody(other)
        else:  # self-collision off again: the robot's links in a group of their own that
            # their mask leaves out (the ground, static group 2, still collides with them)
            for index in self.link_names:
                p.setCollisionFilterGroupMask(self.body, index, ROBOT_GROUP, ~ROBOT_GROUP)

        def listing(pairs):
            pairs.sort(key=lambda pair: -pair[2])
            text = ", ".join(f"{a}:{b} ({d * 1000:.1f} mm)" for a, b, d in pairs[:6])
            return text + (f" and {len(pairs) - 6} more" if len(pairs) > 6 else "")

        values = {"pairs": [{"a": a, "b": b, "depth_m": d} for a, b, d in failing],
                  "ancestor_pairs": [{"a": a, "b": b, "depth_m": d} for a, b, d in ancestral],
                  "loop_cut_pairs": [{"a": a, "b": b, "depth_m": d} for a, b, d in looped],
                  "srdf": prepared.srdf, "srdf_pairs": len(prepared.srdf_pairs)}
        extra = ""
        if ancestral:
            extra += (f"; not counted (--no-strict-collision): {len(ancestral)} overlap(s) of a "
                      f"link with an ancestor two or more joints up, {listing(ancestral)}")
        if looped:
            extra += (f"; allowed: {len(looped)} overlap(s) where a closed chain is cut (links "
                      f"moved by one mimic group), {listing(looped)}")
        if prepared.srdf:
            extra += f"; {len(prepared.srdf_pairs)} pair(s) allowed by {prepared.srdf}"
        if failing:
            return _check("self-collision", "fail",
                          f"{len(failing)} pair(s) of non-adjacent links overlap at the home pose: "
                          f"{listing(failing)} (allow a pair with --allow-collision A:B)" + extra,
                          **values)
        return _check("self-collision", "pass",
                      "no non-adjacent links overlap at the home pose" + extra, **values)

    def _place(self) -> None:
        p = self.client
        lowest = min((p.getAABB(self.body, i)[0][2] for i in self.collision_links), default=None)
        position, orientation = p.getBasePositionAndOrientation(self.body)
        lift = 0.0
        if lowest is not None:
            if not self.prepared.anchored:
                lift = DROP_GAP - lowest
            elif lowest < ANCHOR_GAP:
                lift = ANCHOR_GAP - lowest
        p.resetBasePositionAndOrientation(self.body, (position[0], position[1], position[2] + lift),
                                          orientation)
        self.start_position, self.start_orientation = p.getBasePositionAndOrientation(self.body)

    # -- stepping ------------------------------------------------------------------------------

    def _step(self) -> None:
        import numpy as np

        p, body = self.client, self.body
        steps = max(1, round(self.options.duration * self.options.rate))
        dt = 1.0 / self.options.rate
        indices = [i for i in self.link_names if i >= 0]
        names = [self.link_names[-1]] + [self.link_names[i] for i in indices]
        masses = np.array([self.masses[-1]] + [self.masses[i] for i in indices])
        inertia = np.array([p.getDynamicsInfo(body, -1)[2]] +
                           [p.getDynamicsInfo(body, i)[2] for i in indices])
        if self.prepared.anchored:
            masses[0], inertia[0] = 0.0, 0.0
        self.moving_mass = float(masses.sum())
        joint_ids = [i for i, _ in self.controlled]
        lower = np.array([f.lower if f.lower is not None and not f.empty_range else -np.inf
                          for _, f in self.controlled])
        upper = np.array([f.upper if f.upper is not None and not f.empty_range else np.inf
                          for _, f in self.controlled])
        self.limit_excess = np.zeros(len(joint_ids))
        self.limit_excess_time = np.zeros(len(joint_ids))
        torque_sum = np.zeros(len(joint_ids))
        torque_count = 0
        energy = np.zeros(steps)
        base_xy = np.zeros((steps, 3))
        max_speed = max_angular = 0.0
        speed_where = angular_where = (names[0], 0.0)
        penetrations: list[float] = []
        self.nan_at = None
        late = int(steps * 0.75)
        torque_from = int(steps * 0.9)
        started = time.perf_counter()
        step = 0
        for step in range(steps):
            p.stepSimulation()
            position, orientation = p.getBasePositionAndOrientation(body)
            linear, angular = p.getBaseVelocity(body)
            states = p.getLinkStates(body, indices, computeLinkVelocity=1) if indices else []
            lin = np.array([linear] + [s[6] for s in states])
            ang = np.array([angular] + [s[7] for s in states])
            orn = np.array([orientation] + [s[1] for s in states])
            if joint_ids:
                joint_states = p.getJointStates(body, joint_ids)
                q = np.array([s[0] for s in joint_states])
                if step >= torque_from:
                    torque_sum += np.abs([s[3] for s in joint_states])
                    torque_count += 1
            else:
                q = np.zeros(0)
            finite = (np.isfinite(lin).all() and np.isfinite(ang).all() and np.isfinite(orn).all()
                      and np.isfinite(q).all() and all(map(math.isfinite, position)))
            if not finite:
                bad = [names[k] for k in range(len(names))
                       if not (np.isfinite(lin[k]).all() and np.isfinite(ang[k]).all())]
                self.nan_at = ((step + 1) * dt, bad[0] if bad else names[0])
                break
            speeds = np.linalg.norm(lin, axis=1)
            spins = np.linalg.norm(ang, axis=1)
            k = int(speeds.argmax())
            if speeds[k] > max_speed:
                max_speed, speed_where = float(speeds[k]), (names[k], (step + 1) * dt)
            k = int(spins.argmax())
            if spins[k] > max_angular:
                max_angular, angular_where = float(spins[k]), (names[k], (step + 1) * dt)
            energy[step] = 0.5 * float((masses * speeds ** 2).sum()) + \
                0.5 * float((inertia * _local(orn, ang) ** 2).sum())
            base_xy[step] = position
            if len(q):
                excess = np.maximum(lower - q, q - upper)
                worse = excess > self.limit_excess
                self.limit_excess = np.where(worse, excess, self.limit_excess)
                self.limit_excess_time = np.where(worse, (step + 1) * dt, self.limit_excess_time)
            if step >= late and step % 4 == 0 and not self.prepared.anchored:
                contacts = p.getContactPoints(body, self.plane)
                if contacts:
                    penetrations.append(max(0.0, -min(c[8] for c in contacts)))
        elapsed = time.perf_counter() - started
        self.result.timing["simulate"] = elapsed
        self.steps_done = step + 1
        self.simulated = self.steps_done * dt
        self.result.real_time_factor = self.simulated / elapsed if elapsed > 0 else None
        self.energy, self.base_path = energy[:self.steps_done], base_xy[:self.steps_done]
        self.max_speed, self.speed_where = max_speed, speed_where
        self.max_angular, self.angular_where = max_angular, angular_where
        self.penetration = float(np.median(penetrations)) if penetrations else 0.0
        self.contact_samples = len(penetrations)
        self.final_q = q if self.nan_at is None else None
        self.mean_torque = torque_sum / torque_count if torque_count else None
        self.final_orientation = orientation

    # -- judging -------------------------------------------------------------------------------

    def _judge(self) -> None:
        checks = self.result.checks
        if self.nan_at is not None:
            when, link = self.nan_at
            checks.append(_check("nan", "fail", f"the state became NaN/infinite at t={when:.3f} s "
                                 f"(link '{link}')", time_s=when, link=link))
            checks.append(self._explosion())
            _skip_rest(self.result, "the state became NaN")
            return
        checks.append(_check("nan", "pass", f"state finite through {self.simulated:g} s"))
        checks.append(self._explosion())
        checks.append(self._joint_limits())
        checks.append(self._hold())
        checks.append(self._settle())
        if self.prepared.anchored:
            reason = f"anchored ({self.prepared.anchor_reason})"
            checks.append(_check("sink", "skip", reason))
            checks.append(_check("drift", "skip", reason))
        else:
            checks.append(self._sink())
            checks.append(self._drift())

    def _explosion(self) -> CheckResult:
        limits = self.limits
        values = {"max_speed_mps": self.max_speed, "max_speed_link": self.speed_where[0],
                      "max_angular_radps": self.max_angular, "max_angular_link": self.angular_where[0]}
        text = (f"fastest link '{self.speed_where[0]}' {self.max_speed:.3g} m/s at "
                f"t={self.speed_where[1]:.3f} s, fastest spin '{self.angular_where[0]}' "
                f"{self.max_angular:.3g} rad/s at t={self.angular_where[1]:.3f} s")
        if self.max_speed > limits.max_speed or self.max_angular > limits.max_angular_speed:
            return _check("explosion", "fail", f"{text} (bounds {limits.max_speed:g} m/s, "
                          f"{limits.max_angular_speed:g} rad/s)", **values)
        return _check("explosion", "pass", text, **values)

    def _joint_limits(self) -> CheckResult:
        limits = self.limits
        problems, values = [], []
        for (index, fact), excess, when in zip(self.controlled, self.limit_excess,
                                               self.limit_excess_time):
            if fact.empty_range:
                problems.append(f"'{fact.name}': lower {fact.lower:g} > upper {fact.upper:g}, an "
                                "empty range (PyBullet enforces no limit at all)")
                values.append({"joint": fact.name, "lower": fact.lower, "upper": fact.upper,
                               "empty_range": True})
                continue
            if fact.lower is None or fact.upper is None:
                continue
            tolerance = limits.limit_tolerance_linear if fact.linear else limits.limit_tolerance
            if excess > tolerance:
                unit = "m" if fact.linear else "rad"
                problems.append(f"'{fact.name}' went {excess:.3g} {unit} past "
                                f"[{fact.lower:g}, {fact.upper:g}] at t={when:.3f} s")
                values.append({"joint": fact.name, "lower": fact.lower, "upper": fact.upper,
                               "excess": float(excess), "time_s": float(when)})
        if problems:
            return _check("joint-limits", "fail", "; ".join(problems[:6]) +
                          (f" and {len(problems) - 6} more" if len(problems) > 6 else ""),
                          joints=values)
        limited = sum(1 for _, f in self.controlled if f.lower is not None)
        return _check("joint-limits", "pass", f"{limited} limited joint(s) stayed within their "
                      "limits", joints=values)

    def _hold(self) -> CheckResult:
        limits = self.limits
        off = []
        for k, (index, fact) in enumerate(self.controlled):
            error = float(self.final_q[k] - fact.home)
            if fact.type == "continuous":
                error = math.remainder(error, 2 * math.pi)
            tolerance = limits.hold_tolerance_linear if fact.linear else limits.hold_tolerance
            if abs(error) > tolerance:
                off.append((k, fact, error))
        if not off:
            return _check("hold", "pass", f"{len(self.controlled)} joint(s) held the home pose",
                          joints=[])
        self.result.saturation = self._saturation(off)
        parts = []
        held = "" if self.prepared.anchored else ", base held"
        for entry in self.result.saturation[:6]:
            linear = entry["linear"]
            unit, torque = ("m", "N") if linear else ("rad", "N·m")
            text = f"'{entry['joint']}' is {entry['error']:+.3g} {unit} off its home {entry['home']:g}"
            needed, effort, applied = entry["gravity_torque"], entry["effort"], \
                entry["applied_torque"]
            limit = "no effort limit" if effort is None else f"effort limit {effort:g} {torque}"
            if entry["saturated_by"] == "gravity":
                text += (f": gravity needs {abs(needed):.3g} {torque} there (pinocchio RNEA"
                         f"{held}), its {limit} is less, so it saturates")
            elif entry["saturated_by"] == "load":
                text += (f": its motor pushes at its {limit} (PyBullet)"
                         + (f" though gravity needs only {abs(needed):.3g} {torque}"
                            if needed is not None else "") +
                         ": something else loads it (a contact, a fall)")
            elif needed is not None:
                text += (f" with its motor below its {limit} (gravity needs {abs(needed):.3g} "
                         f"{torque}, PyBullet applies "
                         f"{'?' if applied is None else f'{applied:.3g}'}): the simulation "
                         "cannot hold the joint (tiny inertia or mass?)")
            parts.append(text)
        more = f" and {len(off) - 6} more" if len(off) > 6 else ""
        return _check("hold", "fail", "cannot hold the home pose: " + "; ".join(parts) + more,
                      joints=self.result.saturation)

    def _saturation(self, off) -> list[dict]:
        torques: dict[str, float] = {}
        try:
            from urdftool.sim.gravity import gravity_torques

            torques = gravity_torques(self.prepared.urdf_text,
                                      {f.name: f.home for _, f in self.controlled})
        except Exception as exc:  # noqa: BLE001 - pinocchio missing or refusing the model
            self.result.notes.append(f"no gravity torques from pinocchio: {exc}")
        entries = []
        for k, fact, error in off:
            applied = float(self.mean_torque[k]) if self.mean_torque is not None else None
            needed = torques.get(fact.name)
            effort = fact.effort
            by_gravity = effort is not None and needed is not None and abs(needed) > effort
            by_load = effort is not None and applied is not None and applied >= 0.98 * effort
            saturated = by_gravity or by_load
            entries.append({"joint": fact.name, "home": fact.home, "error": error,
                            "linear": fact.linear, "effort": effort, "gravity_torque": needed,
                            "applied_torque": applied, "saturated": bool(saturated),
                            "saturated_by": "gravity" if by_gravity else "load" if by_load
                            else None})
        entries.sort(key=lambda e: (not e["saturated"], -abs(e["error"])))
        return entries

    def _settle(self) -> CheckResult:
        limits = self.limits
        energy = self.energy
        final = float(energy[-1])
        mass = self.moving_mass or 1.0
        speed = math.sqrt(max(0.0, 2.0 * final / mass))
        values = {"kinetic_energy_j": final, "rms_speed_mps": speed}
        if speed <= limits.settle_speed:
            return _check("settle", "pass", f"kinetic energy {final:.3g} J at the end (RMS speed "
                          f"{speed:.3g} m/s)", **values)
        quarter = max(1, len(energy) // 4)
        earlier = float(energy[-2 * quarter:-quarter].max()) if len(energy) >= 2 * quarter else None
        later = float(energy[-quarter:].max())
        values.update(peak_third_quarter_j=earlier, peak_last_quarter_j=later)
        if earlier is not None and later < 0.8 * earlier:
            return _check("settle", "pass", f"still moving (kinetic energy {final:.3g} J, RMS "
                          f"speed {speed:.3g} m/s) but decaying: peak {later:.3g} J in the last "
                          f"quarter vs {earlier:.3g} J before", **values)
        hint = ""
        if not self.prepared.anchored:
            hint = ("; the base is free (the root link is not 'world'): if the robot is bolted "
                    "down (an arm), run with --fixed-base, or add a 'world' link and a fixed "
                    "joint to it")
        return _check("settle", "fail", f"does not settle: kinetic energy {final:.3g} J at "
                      f"t={self.simulated:g} s (RMS speed {speed:.3g} m/s, bound "
                      f"{limits.settle_speed:g}), not decaying" + hint, **values)

    def _sink(self) -> CheckResult:
        p, limits = self.client, self.limits
        if not self.collision_links:
            return _check("sink", "fail", "no collision geometry at all: the model falls through "
                          "the ground", penetration_m=None)
        boxes = [p.getAABB(self.body, i) for i in self.collision_links]
        lowest, top = min(b[0][2] for b in boxes), max(b[1][2] for b in boxes)
        below = []
        for index, name in self.link_names.items():
            if index in self.collision_links:
                continue
            z = (p.getBasePositionAndOrientation(self.body)[0][2] if index < 0
                 else p.getLinkState(self.body, index)[4][2])
            if z < -limits.sink_depth:
                below.append((name, z))
        values = {"penetration_m": self.penetration, "lowest_point_m": lowest, "top_point_m": top,
                      "frames_below_ground": [{"link": n, "z_m": z} for n, z in below]}
        note = ""
        if below:
            note = ("; links without collision geometry end up below the ground: " + ", ".join(
                f"'{n}' at z={z:.3g} m" for n, z in below[:5]) +
                (f" and {len(below) - 5} more" if len(below) > 5 else ""))
        if top < 0 or (self.contact_samples == 0 and lowest < -limits.sink_depth):
            return _check("sink", "fail", f"fell through the ground: collision geometry spans "
                          f"z={lowest:.3g}..{top:.3g} m at the end" + note, **values)
        if self.penetration > limits.sink_depth:
            return _check("sink", "fail", f"sinks {self.penetration * 1000:.1f} mm into the ground "
                          f"(median over the last quarter; bound {limits.sink_depth * 1000:g} mm)"
                          + note, **values)
        return _check("sink", "pass", f"rests on the ground, {self.penetration * 1000:.2g} mm "
                      "penetration" + note, **values)

    def _drift(self) -> CheckResult:
        import numpy as np

        limits, path = self.limits, self.base_path
        travel = float(np.linalg.norm(path[-1][:2] - np.asarray(self.start_position[:2])))
        quarter = max(1, len(path) // 4)
        seconds = quarter / self.options.rate
        late_speed = float(np.linalg.norm(path[-1][:2] - path[-1 - quarter][:2]) / seconds) \
            if len(path) > quarter else 0.0
        tilt = _tilt_degrees(self.start_orientation, self.final_orientation)
        values = {"travel_m": travel, "late_speed_mps": late_speed, "tilt_deg": tilt}
        text = (f"base moved {travel * 100:.2f} cm horizontally ({late_speed * 100:.2f} cm/s over "
                f"the last quarter), tilted {tilt:.1f}°")
        if tilt > limits.tilt:
            return _check("drift", "fail", f"tipped over: {text} (bound {limits.tilt:g}°)",
                          **values)
        if travel > limits.drift or late_speed > limits.drift_speed:
            return _check("drift", "fail", f"does not stand still: {text} (bounds "
                          f"{limits.drift * 100:g} cm, {limits.drift_speed * 100:g} cm/s)", **values)
        return _check("drift", "pass", text, **values)


def _local(orientations, angular):
    """Angular velocities in each link's principal inertia frame (quaternions x, y, z, w)."""
    import numpy as np

    x, y, z, w = orientations[:, 0], orientations[:, 1], orientations[:, 2], orientations[:, 3]
    vx, vy, vz = angular[:, 0], angular[:, 1], angular[:, 2]
    # v' = v + w t - q x t with t = -2 q x v (the rotation by the conjugate quaternion)
    tx, ty, tz = -2 * (y * vz - z * vy), -2 * (z * vx - x * vz), -2 * (x * vy - y * vx)
    out = np.empty_like(angular)
    out[:, 0] = vx + w * tx - (y * tz - z * ty)
    out[:, 1] = vy + w * ty - (z * tx - x * tz)
    out[:, 2] = vz + w * tz - (x * ty - y * tx)
    return out


def _tilt_degrees(start, end) -> float:
    """Angle between the base's z axis at the start and at the end."""
    def z_axis(q):
        x, y, z, w = q
        return (2 * (x * z + w * y), 2 * (y * z - w * x), 1 - 2 * (x * x + y * y))

    a, b = z_axis(start), z_axis(end)
    dot = max(-1.0, min(1.0, sum(i * j for i, j in zip(a, b))))
    return math.degrees(math.acos(dot))
