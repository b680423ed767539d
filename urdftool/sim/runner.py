"""Worker processes for ``urdftool sim``: each model runs in a child process.

Two reasons besides ``-j N``: PyBullet writes from C to file descriptor 1 (a worker's fds 1 and
2 point at /dev/null, so nothing reaches our stdout or a JSON report), and PyBullet crashes on
some broken models (a segmentation fault takes only the worker down; the model is re-run alone
to find which one it was, and that one fails its load check).
"""

from __future__ import annotations

import multiprocessing
import os
from concurrent.futures import ProcessPoolExecutor, as_completed
from concurrent.futures.process import BrokenProcessPool
from pathlib import Path

from urdftool.errors import ToolError
from urdftool.sim import CHECKS, CheckResult, ModelResult, SimOptions

# what a model costs a worker (PyBullet's load and 240 steps; pybullet_data and
# example-robot-data on one 2-core machine: 30 to 180 ms CPU, ~1.3 us per byte of the file):
# a handful of models is simulated by one worker, the pool grows with the work (issue 15)
SECONDS_PER_MODEL = 0.05
SECONDS_PER_BYTE = 1.5e-6


def _init_worker() -> None:
    devnull = os.open(os.devnull, os.O_WRONLY)
    os.dup2(devnull, 1)
    os.dup2(devnull, 2)
    os.close(devnull)
    from urdftool.sim.capture import captured_fds

    with captured_fds():
        import pybullet  # noqa: F401 - the banner goes to the capture
        import pybullet_data  # noqa: F401


def _with_args(options: SimOptions, args: dict[str, str]) -> SimOptions:
    """``options`` expanding with an entry's arguments (the operator's ``NAME:=VALUE`` win)."""
    import dataclasses

    return dataclasses.replace(options, xacro_args={**args, **options.xacro_args}) \
        if args else options


def _work(path: str, options: SimOptions, from_directory: bool,
          picture: str | None) -> ModelResult:
    from urdftool.sim.engine import run_model

    return run_model(path, options, from_directory, picture)


def picture_paths(files: list[str], render: str | None) -> list[str | None]:
    """Where each model's picture goes. One model and a file name: that file. A directory (an
    existing one, or a name ending in '/'): DIR/MODEL.png. Several models and a file name
    NAME.png: NAME-MODEL.png beside it. MODEL is the file name without .urdf/.xacro/.sdf (the whole
    file name, then the folder in front, when two models would share it)."""
    if not render:
        return [None] * len(files)
    def plain(name: str) -> str:
        while Path(name).suffix in (".urdf", ".xacro", ".sdf"):
            name = name[:-len(Path(name).suffix)]
        return name or "model"

    names = [plain(Path(f).name) for f in files]
    names = [Path(f).name.replace(".", "_") if names.count(n) > 1 else n
             for f, n in zip(files, names)]
    names = [f"{Path(f).parent.name}_{n}" if names.count(n) > 1 else n
             for f, n in zip(files, names)]
    seen: dict[str, int] = {}
    for index, name in enumerate(names):  # still equal: number them
        seen[name] = seen.get(name, 0) + 1
        if seen[name] > 1:
            names[index] = f"{name}-{seen[name]}"
    target = Path(render)
    if target.is_dir() or render.endswith(("/", os.sep)):
        return [str(target / f"{name}.png") for name in names]
    if len(files) == 1:
        return [str(target if target.suffix.lower() == ".png" else target.with_suffix(".png"))]
    stem = target.name[:-len(target.suffix)] if target.suffix else target.name
    return [str(target.with_name(f"{stem}-{name}.png")) for name in names]


def _check_pictures(pictures: list[str | None], inputs: list[str]) -> None:
    """Refuse (exit 2, before any simulation) a picture that would be written through a
    symbolic link or over an input: the workers' writes would refuse it too, one by one."""
    from urdftool.output import check_target

    for picture in filter(None, pictures):
        collision = Path(picture).with_name(Path(picture).stem + "-collision.png")
        for target in (picture, str(collision)):
            check_target(target, inputs, make_dirs=True)


def _context():
    methods = multiprocessing.get_all_start_methods()
    return multiprocessing.get_context("fork" if "fork" in methods else "spawn")


def model_files(paths: list[str], options: SimOptions | None = None,
                ) -> list[tuple[str, bool, dict[str, str]]]:
    """(file, found in a directory, its xacro arguments) for every model under ``paths``. A
    file named is simulated as it is; in a directory, the entries ``check DIR`` finds, each
    with the arguments it expands them with (a launch file's, a configuration's): its
    fragments (macro files, included parts) are no robots to drop into a simulator."""
    from urdftool.source import discover

    files: list[tuple[str, bool, dict[str, str]]] = []
    for raw in paths:
        if Path(raw).is_dir():
            files.extend((path, True, args) for path, args in _entries(raw, options))
        else:
            files.extend((str(f), False, {}) for f in discover([raw]))
    if not files:
        raise ToolError("no robot files (*.urdf, *.xacro, *.sdf) found in " + ", ".join(paths))
    return files


def _entries(directory: str, options: SimOptions | None) -> list[tuple[str, dict[str, str]]]:
    """The entries of ``check DIRECTORY`` (with the operator's options of this run) and their
    xacro arguments."""
    from urdftool.check import CheckOptions, check_paths
    from urdftool.errors import NothingToCheck
    from urdftool.source import LoadOptions

    options = options or SimOptions()
    load = LoadOptions(dict(options.packages), dict(options.xacro_args),
                       allow_env=options.allow_env, timeout=options.timeout,
                       memory_mb=options.memory_mb)
    load.untrusted = options.untrusted
    try:
        report = check_paths([directory], CheckOptions(load=load))
    except NothingToCheck:
        return []
    return [(f.path, dict(f.args)) for f in report.files if f.role == "entry"]


def _crashed(path: str, code: str) -> ModelResult:
    result = ModelResult(path=path)
    result.checks.append(CheckResult("sim.load", "fail", f"PyBullet crashed on this model ({code})"))
    result.checks.extend(CheckResult(f"sim.{name}", "skip", "the model did not load")
                         for name in CHECKS if name != "load")
    return result


def run_all(paths: list[str], options: SimOptions, progress=None) -> list[ModelResult]:
    files = model_files(paths, options)
    require_pybullet()
    pictures = picture_paths([f for f, _, _ in files], options.render)
    _check_pictures(pictures, [f for f, _, _ in files])
    results: list[ModelResult | None] = [None] * len(files)
    from urdftool.check import default_jobs

    steps = options.duration * options.rate / 240  # the default 1 s at 240 Hz is 1
    jobs = max(1, min(options.jobs or default_jobs(
        [f for f, _, _ in files], SECONDS_PER_MODEL * max(steps, 1), SECONDS_PER_BYTE),
        len(files)))
    context = _context()
    try:
        with ProcessPoolExecutor(jobs, mp_context=context, initializer=_init_worker) as pool:
            futures = {pool.submit(_work, path, _with_args(options, args), from_directory,
                                   pictures[index]): index
                       for index, (path, from_directory, args) in enumerate(files)}
            for done, future in enumerate(as_completed(futures), start=1):
                if progress is not None:
                    progress(done, len(files))
                try:
                    results[futures[future]] = future.result()
                except BrokenProcessPool:
                    continue
    except BrokenProcessPool:
        pass
    for index, result in enumerate(results):  # after a crash: each unfinished model alone
        if result is None:
            path, from_directory, args = files[index]
            with ProcessPoolExecutor(1, mp_context=context, initializer=_init_worker) as pool:
                try:
                    results[index] = pool.submit(_work, path, _with_args(options, args),
                                                 from_directory, pictures[index]).result()
                except BrokenProcessPool:
                    results[index] = _crashed(path, "the worker process died")
    return [r for r in results if r is not None]


def require_pybullet() -> None:
    """A ToolError (exit 2) naming the extra when pybullet is not installed."""
    import importlib.util

    if importlib.util.find_spec("pybullet") is None:
        from urdftool.errors import install_line

        raise ToolError(f"'sim' needs the 'pybullet' module: {install_line('sim')}")


def simulate(paths: list[str], options: SimOptions | None = None,
             progress=None) -> list[ModelResult]:
    """Simulate every robot file under ``paths`` (directories searched like ``check``).
    Raises ToolError when there is nothing to simulate or a file cannot be read.
    ``progress(done, total)`` is called as models finish."""
    return run_all(paths, options or SimOptions(), progress)
