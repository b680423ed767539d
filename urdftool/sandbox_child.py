"""The sandboxed reader: a fresh interpreter (``python -I``, started by ``urdftool.sandbox`` with
a near-empty environment) that reads untrusted files and answers in JSON.

Protocol, one JSON document per line: the parent's first line gives the confinement (the
directories the child may read, its memory and CPU limits); the child confines itself (see
``confine``) and answers with the layers it holds; then each request line gets one answer line.
Requests: ``load`` (a xacro or SDF file into a Source, sent back as tagged XML and its
locations), ``convert`` (``urdftool convert`` of an SDF file) and ``mesh`` (a mesh file's
summary). The child never receives or sends pickle, and
nothing in it outlives its run.
"""

from __future__ import annotations

import gc
import json
import os
import select
import sys

MAX_REQUEST_BYTES = 1 << 20
IDLE_SECONDS = 0.05  # no request for this long after an expansion: its garbage is collected
LIBRARY_PRELOAD = ("lxml.etree", "yaml", "xacro", "urdftool.loader", "urdftool.xacro_expand",
                   "urdftool.sdf")

# errno values (the errno module is tiny, but these are all we need)
EPERM, ENOSYS = 1, 38
CLONE_THREAD = 0x00010000

# the system calls the reader makes once confined (traced on xacro, YAML, SDF and STL/DAE/OBJ
# mesh requests, numpy and trimesh imported after the filter): reading files through
# descriptors, memory, threads, clocks, exit. Every other call is refused (EPERM): no process,
# program, socket, SysV or POSIX IPC, ptrace, namespace, mount, key, BPF, io_uring... Calls
# with arguments that matter are allowed only with harmless ones (see ``_seccomp``).
ALLOWED_SYSCALLS = (
    # files, through descriptors opened read-only (openat/open: see _seccomp)
    "read", "pread64", "readv", "preadv", "preadv2", "lseek", "close", "fstat", "newfstatat",
    "stat", "lstat", "statx", "fstatfs", "statfs", "getdents64", "getdents", "readlink",
    "readlinkat", "access", "faccessat", "faccessat2", "getcwd", "dup", "dup3",
    # memory
    "brk", "mmap", "munmap", "mprotect", "mremap", "madvise", "mbind", "get_mempolicy",
    "membarrier",
    # threads and their synchronisation (clone: threads only, see _seccomp)
    "futex", "futex_waitv", "set_robust_list", "get_robust_list", "set_tid_address", "rseq",
    "sched_yield", "sched_getaffinity", "sched_getparam", "sched_getscheduler", "getcpu",
    # signals to itself (kill/tgkill: its own pid only, see _seccomp); its own interval timer
    # (SIGALRM to itself: budget.watchdog stops xacro's and PyYAML's own loops at the deadline)
    "rt_sigaction", "rt_sigprocmask", "rt_sigreturn", "sigaltstack", "rt_sigpending",
    "rt_sigtimedwait", "rt_sigsuspend", "setitimer", "getitimer", "alarm",
    # clocks, identity, randomness, limits read
    "clock_gettime", "clock_getres", "clock_nanosleep", "nanosleep", "gettimeofday", "time",
    "getpid", "gettid", "getppid", "getuid", "geteuid", "getgid", "getegid", "getresuid",
    "getresgid", "getgroups", "getpgrp", "getpgid", "getsid", "uname", "sysinfo", "getrusage",
    "times", "getrandom", "getrlimit", "getpriority", "capget",
    # waiting on its pipes
    "poll", "ppoll", "select", "pselect6",
    # the end
    "exit", "exit_group",
)
O_ACCMODE, O_CREAT, O_TRUNC, O_ASYNC = 0o3, 0o100, 0o1000, 0o20000
# fcntl commands that read or set a descriptor's own flags (F_SETFL: never O_ASYNC, see
# _seccomp); F_SETOWN, F_SETSIG, F_SETOWN_EX, F_SETLEASE, F_NOTIFY (signals to any process of
# the user) and locks are refused
F_DUPFD, F_GETFD, F_SETFD, F_GETFL, F_SETFL, F_DUPFD_CLOEXEC = 0, 1, 2, 3, 4, 1030
# ioctl requests: is this a terminal, its size (ioctl's FIOASYNC/FIOSETOWN are refused)
TCGETS, TIOCGWINSZ = 0x5401, 0x5413
# prctl options the C library and the interpreter use: thread names, capability bounding set
# read, anonymous memory names (glibc's malloc arenas)
PR_SET_NAME, PR_GET_NAME, PR_CAPBSET_READ, PR_GET_DUMPABLE, PR_SET_VMA = 15, 16, 23, 3, 0x53564D41


def _set_limits(memory_mb: int, cpu_seconds: int, nofile: int) -> dict[str, int]:
    """Hard limits (soft = hard): a process can only lower them (and, without
    CAP_SYS_RESOURCE, which ``_drop_capabilities`` removes from root, never raise them)."""
    import resource
    import signal

    signal.signal(signal.SIGXFSZ, signal.SIG_IGN)  # a write fails (EFBIG) rather than kills
    wanted = {"RLIMIT_AS": memory_mb << 20, "RLIMIT_CPU": cpu_seconds, "RLIMIT_FSIZE": 0,
              "RLIMIT_NOFILE": nofile, "RLIMIT_NPROC": 0, "RLIMIT_CORE": 0}
    applied = {}
    for name, value in wanted.items():
        which = getattr(resource, name, None)
        if which is None:
            continue
        _, hard = resource.getrlimit(which)
        if hard != resource.RLIM_INFINITY:
            value = min(value, hard)
        resource.setrlimit(which, (value, value))
        applied[name] = value
    return applied


def _drop_capabilities() -> None:
    """Empty effective, permitted and inheritable capability sets (matters when run as root,
    as CI runners often are: CAP_SYS_RESOURCE could raise a hard limit, CAP_SYS_PTRACE read
    another process's memory)."""
    import ctypes

    class Header(ctypes.Structure):
        _fields_ = [("version", ctypes.c_uint32), ("pid", ctypes.c_int)]

    class Data(ctypes.Structure):
        _fields_ = [("effective", ctypes.c_uint32), ("permitted", ctypes.c_uint32),
                    ("inheritable", ctypes.c_uint32)]

    libc = ctypes.CDLL(None, use_errno=True)
    header = Header(0x20080522, 0)  # _LINUX_CAPABILITY_VERSION_3: two Data structures
    data = (Data * 2)()
    if libc.capset(ctypes.byref(header), data) != 0:
        raise OSError(ctypes.get_errno(), "capset")


def _no_new_privs() -> None:
    import ctypes

    libc = ctypes.CDLL(None, use_errno=True)
    if libc.prctl(38, 1, 0, 0, 0) != 0:  # PR_SET_NO_NEW_PRIVS
        raise OSError(ctypes.get_errno(), "prctl(PR_SET_NO_NEW_PRIVS)")


# Landlock beyond files, by ABI version: TCP bind and connect (4); abstract unix sockets and
# signals scoped to the sandbox (6). The landlock package's ruleset knows only the file
# accesses (its RulesetAttr has one field): the ruleset is created here with the kernel's full
# landlock_ruleset_attr, and its rules added and enforced through the package's calls.
NET_BIND_TCP, NET_CONNECT_TCP = 1 << 0, 1 << 1
SCOPE_ABSTRACT_UNIX_SOCKET, SCOPE_SIGNAL = 1 << 0, 1 << 1
NET_ABI, SCOPE_ABI = 4, 6


def _landlock(read: list[str]) -> dict[str, str]:
    """Read-only access beneath ``read``, nothing else (no write, create, remove, execute)
    anywhere; no TCP bind or connect, and no signal or abstract unix socket reaching outside
    the sandbox, where the kernel's ABI has them. Returns the layers ("landlock",
    "landlock_net", "landlock_scopes"); raises when the kernel has no Landlock."""
    import ctypes

    import landlock
    from landlock import plumbing

    abi = landlock.landlock_abi_version()
    handled = landlock.FSAccess.all()
    net = NET_BIND_TCP | NET_CONNECT_TCP if abi >= NET_ABI else 0
    scoped = SCOPE_ABSTRACT_UNIX_SOCKET | SCOPE_SIGNAL if abi >= SCOPE_ABI else 0

    class RulesetAttr(ctypes.Structure):  # struct landlock_ruleset_attr
        _fields_ = [("handled_access_fs", ctypes.c_uint64),
                    ("handled_access_net", ctypes.c_uint64), ("scoped", ctypes.c_uint64)]

    attr = RulesetAttr(int(handled), net, scoped)
    size = 24 if abi >= SCOPE_ABI else 16 if abi >= NET_ABI else 8  # what this ABI reads
    libc = plumbing.get_libc()
    libc.syscall.restype = ctypes.c_long
    ruleset = libc.syscall(ctypes.c_long(plumbing.SYSCALL_CREATE_RULESET), ctypes.byref(attr),
                           ctypes.c_size_t(size), ctypes.c_uint32(0))
    if ruleset < 0:
        raise OSError(ctypes.get_errno(), "landlock_create_ruleset")
    try:
        allowed = landlock.FSAccess.READ_FILE | landlock.FSAccess.READ_DIR
        for directory in read:
            if os.path.exists(directory):
                rules = allowed if os.path.isdir(directory) else landlock.FSAccess.READ_FILE
                parent = os.open(directory, os.O_PATH)
                try:
                    plumbing.get_add_rule()(ruleset, 1, ctypes.byref(
                        plumbing.PathBeneathAttr(rules, parent)), 0)
                finally:
                    os.close(parent)
        plumbing.get_restrict_self()(ruleset, 0)
    finally:
        os.close(ruleset)
    return {"landlock": f"abi {abi}",
            "landlock_net": "TCP bind and connect denied" if net
            else f"off: kernel Landlock ABI {abi} < {NET_ABI}",
            "landlock_scopes": "signals and abstract unix sockets kept inside" if scoped
            else f"off: kernel Landlock ABI {abi} < {SCOPE_ABI}"}


def _seccomp() -> str:
    """Default deny (EPERM): only ``ALLOWED_SYSCALLS`` and, with their arguments checked,
    ``openat``/``open`` read-only (no create, truncate or O_ASYNC), ``write`` to its answer
    channel and stderr, ``fcntl`` on a descriptor's own flags without O_ASYNC, ``ioctl``
    asking whether a descriptor is a terminal, ``prctl`` for names and reads, ``clone`` of a
    thread (not a process), ``kill``/``tgkill`` of itself, ``prlimit64`` reading. ``clone3``
    answers ENOSYS so that the C library falls back to ``clone``, which the filter can
    inspect."""
    import pyseccomp as seccomp

    me = os.getpid()
    rules = seccomp.SyscallFilter(defaction=seccomp.ERRNO(EPERM))
    allow = seccomp.ALLOW
    allowed, checked = set(), set()

    def add(name: str, *args) -> None:
        try:
            rules.add_rule(allow, name, *args)
        except (OSError, ValueError, RuntimeError):  # a call this architecture does not have
            return
        (checked if args else allowed).add(name)

    for name in ALLOWED_SYSCALLS:
        add(name)
    refused_flags = O_ACCMODE | O_CREAT | O_TRUNC | O_ASYNC
    add("openat", seccomp.Arg(2, seccomp.MASKED_EQ, refused_flags, 0))
    add("open", seccomp.Arg(1, seccomp.MASKED_EQ, refused_flags, 0))
    for fd in (1, 2):  # the answer channel, stderr (the parent keeps what it says)
        add("write", seccomp.Arg(0, seccomp.EQ, fd))
        add("writev", seccomp.Arg(0, seccomp.EQ, fd))
    for command in (F_DUPFD, F_GETFD, F_SETFD, F_GETFL, F_DUPFD_CLOEXEC):
        add("fcntl", seccomp.Arg(1, seccomp.EQ, command))
    add("fcntl", seccomp.Arg(1, seccomp.EQ, F_SETFL), seccomp.Arg(2, seccomp.MASKED_EQ, O_ASYNC, 0))
    for request in (TCGETS, TIOCGWINSZ):
        add("ioctl", seccomp.Arg(1, seccomp.EQ, request))
    for option in (PR_SET_NAME, PR_GET_NAME, PR_CAPBSET_READ, PR_GET_DUMPABLE, PR_SET_VMA):
        add("prctl", seccomp.Arg(0, seccomp.EQ, option))
    add("clone", seccomp.Arg(0, seccomp.MASKED_EQ, CLONE_THREAD, CLONE_THREAD))
    rules.add_rule(seccomp.ERRNO(ENOSYS), "clone3")
    add("kill", seccomp.Arg(0, seccomp.EQ, me))
    add("tgkill", seccomp.Arg(0, seccomp.EQ, me))
    add("prlimit64", seccomp.Arg(2, seccomp.EQ, 0))  # reading a limit, never setting one
    rules.load()
    return (f"allowlist: {len(allowed) + len(checked)} calls ({len(checked)} with their "
            "arguments checked), no IPC, sockets, processes, exec or ptrace")


# the dynamic loader's files: extension modules load system libraries (libstdc++...) on import
SYSTEM_LIBRARIES = ("/lib", "/lib64", "/usr/lib", "/usr/lib64", "/usr/local/lib",
                    "/etc/ld.so.cache")


def interpreter_paths() -> list[str]:
    """What the interpreter reads to import modules: the standard library, site-packages,
    urdftool's own package (not the current directory: ``-I`` leaves it out) and the system's
    shared libraries."""
    import urdftool

    paths = {sys.prefix, sys.base_prefix, sys.exec_prefix, sys.base_exec_prefix,
             os.path.dirname(os.path.abspath(urdftool.__file__)), *SYSTEM_LIBRARIES}
    paths.update(entry for entry in sys.path if entry and os.path.isabs(entry))
    return sorted(p for p in paths if os.path.exists(p))


def confine(read: list[str], memory_mb: int, cpu_seconds: int) -> dict[str, str]:
    """Everything this process may do from now on: read the directories ``read`` and the
    interpreter's files, nothing else. Returns each layer and what it holds ("off: why" where
    the kernel or the system lacks it)."""
    layers: dict[str, str] = {}
    modules = {}
    import ctypes.util

    # pyseccomp finds libc and libseccomp with find_library, which runs ldconfig (two
    # processes, ~40 ms): their sonames are stable, so it is given them (any other name: asked)
    find_library = ctypes.util.find_library
    ctypes.util.find_library = lambda name: {"c": "libc.so.6", "seccomp": "libseccomp.so.2"}.get(
        name) or find_library(name)
    try:
        for name in ("landlock", "pyseccomp"):  # imported before any limit
            try:
                modules[name] = __import__(name)
            except Exception as exc:  # noqa: BLE001 - not installed, no libseccomp: said below
                modules[name] = exc
    finally:
        ctypes.util.find_library = find_library
    try:
        _drop_capabilities()
        layers["capabilities"] = "dropped"
    except (OSError, AttributeError) as exc:
        layers["capabilities"] = f"off: {exc}"
    limits = _set_limits(memory_mb, cpu_seconds, nofile=64)
    layers["rlimits"] = (f"hard: address space {limits.get('RLIMIT_AS', 0) >> 20} MB, CPU "
                         f"{limits.get('RLIMIT_CPU')} s, file size 0, 64 files, 0 processes")
    _no_new_privs()
    layers["no_new_privs"] = "on"
    try:
        if isinstance(modules["landlock"], Exception):
            raise modules["landlock"]
        layers.update(_landlock([*read, *interpreter_paths()]))
    except Exception as exc:  # noqa: BLE001 - an old kernel or no landlock module: said
        layers["landlock"] = f"off: {str(exc).splitlines()[0] if str(exc) else type(exc).__name__}"
    try:
        if isinstance(modules["pyseccomp"], Exception):
            raise modules["pyseccomp"]
        layers["seccomp"] = _seccomp()
    except Exception as exc:  # noqa: BLE001 - no libseccomp, or a kernel without seccomp
        layers["seccomp"] = f"off: {str(exc).splitlines()[0] if str(exc) else type(exc).__name__}"
    return layers


# -- requests -------------------------------------------------------------------------------


def _load(request: dict) -> dict:
    from pathlib import Path

    from urdftool import sandbox
    from urdftool.loader import load
    from urdftool.roots import Roots
    from urdftool.source import LoadOptions

    options = LoadOptions(request["packages"], request["xacro_args"],
                          sdf_model=request.get("sdf_model"),
                          sdf_model_paths=request.get("sdf_model_paths") or [], untrusted=True,
                          allow_env=tuple(request["allow_env"]), timeout=request["timeout"])
    options.overlay = {str(k): str(v) for k, v in request.get("overlay", {}).items()}
    options.lenient = request.get("lenient") is True
    options.roots = Roots.from_json(request["roots"])  # the parent's, computed once
    options.in_sandbox = True
    _seed_crawls(request)
    source = load(Path(request["path"]), options)
    return sandbox.source_to_json(source)


def _seed_crawls(request: dict) -> None:
    """The repositories' packages as the parent crawled them (this process may not list a
    repository's own directory: Landlock holds its entries, without its ``.git``)."""
    from pathlib import Path

    from urdftool import packages

    for root, found in (request.get("crawls") or {}).items():
        packages._CRAWLS[str(root)] = {str(name): Path(path) for name, path in found.items()}


def _convert(request: dict) -> dict:
    """``urdftool convert`` of an untrusted SDF file: the Source, and why the conversion was
    refused (a loop with --no-cut) or could not choose a model."""
    from pathlib import Path

    from urdftool import sandbox
    from urdftool.packages import PackageResolver
    from urdftool.roots import Roots
    from urdftool.sdf import ConvertOptions, LoopRefused, ModelChoiceError, convert_guarded
    from urdftool.source import Source, read_text

    path = Path(request["path"])
    _seed_crawls(request)
    resolver = PackageResolver(request["packages"], path, roots=Roots.from_json(request["roots"]),
                               model_paths=tuple(request["model_paths"]))
    text = read_text(path)
    source = Source(str(path), "sdf", texts={str(path): text}, resolver=resolver)
    options = ConvertOptions(model=request["model"], model_paths=request["model_paths"],
                             package_uris=request["package_uris"],
                             output_dir=Path(request["output_dir"]),
                             cut_loops=request["cut_loops"], require_choice=True)
    refused = choice = None
    try:
        convert_guarded(source, path, text, options)
    except ModelChoiceError as exc:
        choice = str(exc)
    except LoopRefused as exc:
        refused = str(exc)
    return {"source": sandbox.source_to_json(source), "refused": refused, "choice": choice}


def _triangles(request: dict) -> dict:
    from pathlib import Path

    from urdftool.physics import meshes

    found = meshes._triangles_here(Path(request["path"]))
    if isinstance(found, str):
        return {"why": found}
    return {"vertices": found[0].ravel().tolist(), "faces": found[1].ravel().tolist()}


def _mesh(request: dict) -> dict:
    from pathlib import Path

    from urdftool.physics import meshes

    header, hull = meshes._encode(meshes._load(Path(request["path"]), request["need_volume"]))
    return {"header": header, "hull": meshes.hull_text(hull)}


def _answer(request) -> dict:
    from urdftool.errors import ToolError
    from urdftool.xacro_eval import LimitExceeded

    try:
        if not isinstance(request, dict):
            return {"error": "a request is a JSON object"}
        op = request.get("op")
        if op == "load":
            return {"ok": _load(request)}
        if op == "mesh":
            return {"ok": _mesh(request)}
        if op == "triangles":
            return {"ok": _triangles(request)}
        if op == "convert":
            return {"ok": _convert(request)}
        return {"error": f"unknown request {op!r}"}
    except ToolError as exc:
        return {"tool_error": str(exc)}
    except MemoryError:
        return {"limit": "out of memory"}
    except (LimitExceeded, RecursionError) as exc:
        return {"limit": str(exc) or type(exc).__name__}
    except Exception as exc:  # noqa: BLE001 - sent to the parent as one line
        from urdftool.errors import exception_text

        return {"error": exception_text(exc)}


def _write(out, payload: dict) -> None:
    try:
        data = json.dumps(payload)
    except (TypeError, ValueError) as exc:
        data = json.dumps({"error": f"unserialisable answer: {exc}"})
    out.write(data.encode("utf-8") + b"\n")
    out.flush()


def main() -> None:
    reader, out = sys.stdin.buffer, sys.stdout.buffer
    sys.stdout = sys.stderr  # anything a library prints stays off the answer channel
    setup = json.loads(reader.readline(MAX_REQUEST_BYTES))
    sys.dont_write_bytecode = True
    for module in LIBRARY_PRELOAD:  # imported before the filter: less to read afterwards
        __import__(module)
    from urdftool import cache, sandbox

    sandbox.IN_CHILD = True
    cache.ENABLED = False  # the parent keeps the persistent cache; the child writes nothing
    layers = confine(setup["read"], setup["memory_mb"], setup["cpu_seconds"])
    _write(out, {"layers": layers})
    if setup.get("test_payload_allowed") and os.environ.get("URDFTOOL_SANDBOX_TEST") == "1":
        _run_test_payload(reader, out)  # tests only: see urdftool.sandbox.run_test_payload
        return
    while True:
        line = reader.readline(MAX_REQUEST_BYTES)
        if not line:
            return
        try:
            request = json.loads(line)
        except ValueError:
            _write(out, {"error": "unreadable request"})
            continue
        _write(out, _answer(request))
        if isinstance(request, dict) and request.get("op") == "load" and \
                not select.select([reader], [], [], IDLE_SECONDS)[0]:
            # an expansion answered and no request since: its garbage (minidom nodes in
            # reference cycles) is collected now rather than inside the next expansion
            gc.collect()


def _run_test_payload(reader, out) -> None:
    """Run the Python source given on the next line, inside the confined child, and answer
    what it returned. Reached only when the parent asked for it at start-up AND the child's
    environment has URDFTOOL_SANDBOX_TEST=1, which only ``sandbox.run_test_payload`` (never
    the CLI) sets: the tests use it to attack the sandbox independently of the xacro
    interpreter."""
    code = json.loads(reader.readline(MAX_REQUEST_BYTES))
    scope: dict = {}
    try:
        exec(code, scope)  # noqa: S102 - test payload, see the docstring
        _write(out, {"ok": scope.get("result")})
    except BaseException as exc:  # noqa: BLE001 - the test reads it
        _write(out, {"error": f"{type(exc).__name__}: {exc}"})


if __name__ == "__main__":
    main()
