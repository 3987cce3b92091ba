"""numba stamps a cached function with its own file, not its callees': the reference ships'
compiled closed loops came back from the cache with the kernel of before an edit to it (a new
autopilot mode ran as a zig-zag and steered the KVLCC2 the other way). ``drop_stale_caches``
deletes a module's numba cache when the kernel's source has changed since it was written."""

import hashlib
from pathlib import Path

from shipid.dynamics import kernel


def _cache(tmp_path):
    module = tmp_path / "ship.py"
    module.write_text("")
    folder = tmp_path / "__pycache__"
    folder.mkdir()
    files = [folder / "ship._closed-1.py311.nbi", folder / "ship._closed-1.py311.1.nbc"]
    other = folder / "other._closed-1.py311.nbi"
    for f in [*files, other]:
        f.write_bytes(b"x")
    return module, files, other, folder / "ship.kernel-sha256"


def test_a_cache_written_with_another_kernel_is_dropped(tmp_path):
    module, files, other, marker = _cache(tmp_path)
    marker.write_text("an older kernel")
    kernel.drop_stale_caches(str(module))
    assert not any(f.exists() for f in files) and other.exists()
    digest = hashlib.sha256(Path(kernel.__file__).read_bytes()).hexdigest()
    assert marker.read_text() == digest


def test_a_cache_of_this_kernel_is_kept(tmp_path):
    module, files, _, marker = _cache(tmp_path)
    marker.write_text(hashlib.sha256(Path(kernel.__file__).read_bytes()).hexdigest())
    kernel.drop_stale_caches(str(module))
    assert all(f.exists() for f in files)


def test_a_cache_without_a_marker_is_dropped(tmp_path):
    module, files, _, marker = _cache(tmp_path)
    kernel.drop_stale_caches(str(module))
    assert not any(f.exists() for f in files) and marker.exists()
