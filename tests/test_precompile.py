"""``python -m shipid.precompile`` (run by ``make install``) calls every compiled kernel."""

from __future__ import annotations

import subprocess
import sys

CHECK = r"""
import importlib, inspect, pkgutil, re, warnings
import numba.core.registry
import shipid
from shipid.precompile import precompile

with warnings.catch_warnings():
    warnings.simplefilter("ignore")
    precompile()
kernels = {}
for info in pkgutil.walk_packages(shipid.__path__, "shipid."):
    if info.name.startswith("shipid.cli"):
        continue
    for name, value in vars(importlib.import_module(info.name)).items():
        if isinstance(value, numba.core.registry.CPUDispatcher) and value.__module__ == info.name:
            kernels[info.name + "." + name] = value
# A kernel's body: its source after the signature.
bodies = {k: re.split(r"\)\s*:[^\n]*\n", inspect.getsource(d.py_func), maxsplit=1)[1]
          for k, d in kernels.items()}


def calls(body, caller, callee):
    module, name = callee.rsplit(".", 1)
    if caller.rsplit(".", 1)[0] == module:
        return re.search(rf"(?<![.\w])(_\w+\.)?{name}\b", body)  # _this.rhs: itself
    return re.search(rf"\b_?{module.rsplit('.', 1)[1]}\.{name}\b", body)


# A kernel another kernel calls is compiled into it (and loaded with it from the cache, so
# its own dispatcher stays empty): only the ones Python calls must have run.
called = {k for k in kernels if any(calls(b, j, k) for j, b in bodies.items() if j != k)}
missed = [k for k, d in kernels.items() if k not in called and not d.signatures]
print(len(kernels), len(called), sorted(missed))
"""


def test_every_compiled_kernel_is_called_once_at_install():
    out = subprocess.run([sys.executable, "-c", CHECK], capture_output=True, text=True,
                         check=True).stdout.split(maxsplit=2)  # fmt: skip
    # The kernels found and those called from other kernels: a broken search would find none.
    assert int(out[0]) >= 30 and 10 <= int(out[1]) < int(out[0])
    assert out[2].strip() == "[]", f"never called by shipid.precompile: {out[2]}"


def test_install_deletes_the_entries_of_kernels_no_longer_cached(tmp_path, monkeypatch):
    """An older install cached ``kernel.open_run`` and ``closed_run``, one entry a process
    (see ``kernel.open_run``); the files are never read again, and the install deletes them,
    leaving the cached kernels' own."""
    from pathlib import Path

    from shipid import precompile
    from shipid.dynamics import kernel

    folder = tmp_path / "__pycache__"
    folder.mkdir()
    monkeypatch.setattr(kernel, "__file__", str(tmp_path / "kernel.py"))
    stale = [folder / "kernel.open_run-280.py311.nbi", folder / "kernel.open_run-280.py311.7.nbc",
             folder / "kernel.closed_run-446.py311.nbi"]  # fmt: skip
    kept = [folder / "kernel.integrate_open-339.py311.nbi", folder / "kernel.steer-357.py311.nbi",
            folder / "mmg._open-120.py311.nbi"]  # fmt: skip
    for f in stale + kept:
        f.write_bytes(b"")
    assert sorted(precompile.drop_uncached_entries()) == sorted(stale)
    assert sorted(Path(folder).iterdir()) == sorted(kept)
