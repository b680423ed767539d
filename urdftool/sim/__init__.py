"""`urdftool sim`: a short PyBullet physics smoke test per model, with a verdict.

The library side of the command. ``runner.simulate(paths, options)`` runs every model in worker
processes (PyBullet crashes or prints from C; neither may reach our stdout or take the run down)
and returns one ``ModelResult`` per model, each with its ``sim.*`` check results. Nothing here
prints or exits; nothing here imports pybullet or pinocchio at module level (``check`` never
pays for them).

Modules: ``prepare`` (source -> a URDF file PyBullet can load, plus what the checks need from the
model), ``engine`` (the PyBullet run and the checks), ``gravity`` (pinocchio RNEA for the joints
that cannot hold the home pose), ``render`` (pictures), ``capture`` (fd-level output capture),
``runner`` (worker processes).
"""

from __future__ import annotations

from dataclasses import asdict, dataclass, field

# The checks, in report order. Each model gets one result per check: pass, fail or skip.
CHECKS = ("load", "mass", "self-collision", "nan", "explosion", "joint-limits", "hold",
          "settle", "sink", "drift")


@dataclass
class Thresholds:
    """The bounds the checks use (SI units)."""

    max_speed: float = 20.0  # m/s, any link: above is an explosion
    max_angular_speed: float = 100.0  # rad/s, any link
    settle_speed: float = 0.05  # m/s, RMS speed from the kinetic energy at the end
    limit_tolerance: float = 0.05  # rad past a revolute limit
    limit_tolerance_linear: float = 0.01  # m past a prismatic limit
    hold_tolerance: float = 0.05  # rad away from the home pose at the end
    hold_tolerance_linear: float = 0.01  # m
    collision_depth: float = 0.003  # m of overlap at the home pose (touching parts: less)
    sink_depth: float = 0.01  # m of penetration into the ground
    drift: float = 0.05  # m of horizontal travel of the base while standing
    drift_speed: float = 0.02  # m/s of horizontal base speed over the last quarter
    tilt: float = 30.0  # degrees: the base tipped over
    mass_tolerance: float = 1e-6  # relative


@dataclass
class SimOptions:
    duration: float = 1.0  # simulated seconds
    rate: float = 240.0  # Hz
    fixed_base: bool | None = None  # None: anchored when the root link is 'world'
    allow_collision: tuple[tuple[str, str], ...] = ()
    srdf: str | bool | None = None  # an SRDF file; None: look for one beside the model; False: none
    strict_collision: bool = True  # also fail on overlaps between a link and its ancestors
    render: str | None = None  # PNG path (or directory) for pictures
    size: tuple[int, int] = (640, 480)
    jobs: int | None = None  # worker processes; None: by the work (check.default_jobs)
    repaired: bool = False  # simulate the XML as urdftool repairs it (past the XML errors)
    packages: dict[str, str] = field(default_factory=dict)
    xacro_args: dict[str, str] = field(default_factory=dict)
    sdf_model: str | None = None  # SDF input: the model of a world (default: the first)
    sdf_model_paths: tuple[str, ...] = ()  # SDF input: where model:// is found
    # untrusted input (see urdftool.sandbox): as LoadOptions
    untrusted: bool = False
    allow_env: tuple[str, ...] = ()
    timeout: float | None = 3.0
    memory_mb: int = 1024
    thresholds: Thresholds = field(default_factory=Thresholds)


@dataclass
class CheckResult:
    """One ``sim.<check>`` result. ``values`` carries the numbers (full precision)."""

    check: str  # "sim.load", "sim.mass", ...
    status: str  # "pass", "fail" or "skip"
    message: str
    values: dict = field(default_factory=dict)

    @property
    def failed(self) -> bool:
        return self.status == "fail"


@dataclass
class ModelResult:
    path: str
    robot: str | None = None
    anchored: bool | None = None
    anchor_reason: str | None = None
    checks: list[CheckResult] = field(default_factory=list)
    timing: dict[str, float] = field(default_factory=dict)  # seconds: prepare, load, ...
    real_time_factor: float | None = None
    links: int | None = None
    joints: int | None = None
    saturation: list[dict] = field(default_factory=list)  # joints that cannot hold the pose
    images: list[str] = field(default_factory=list)
    notes: list[str] = field(default_factory=list)

    @property
    def verdict(self) -> str:
        """'pass', 'fail' (a model that did not load fails its load check) or 'skip' (nothing
        was simulated: a kinematics-only model)."""
        if any(c.failed for c in self.checks):
            return "fail"
        return "skip" if self.checks and all(c.status == "skip" for c in self.checks) else "pass"

    def check(self, name: str) -> CheckResult | None:
        full = name if name.startswith("sim.") else f"sim.{name}"
        return next((c for c in self.checks if c.check == full), None)

    def failures(self) -> list[CheckResult]:
        return [c for c in self.checks if c.failed]

    def to_json(self) -> dict:
        data = asdict(self)
        data["verdict"] = self.verdict
        return data
