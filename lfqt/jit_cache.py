"""numba's on-disk cache of lfqt's kernels, invalidated by a change to any of
lfqt's sources.

numba stamps a cached kernel with its own file's modification time and size
only.  lfqt's kernels inline helpers from other modules (``inline="always"``,
and LLVM inlines the callees it sees too): after an edit of
``lfqt/predicates/planar.py``, the merge kernel of ``lfqt/dc/merge.py``
would load its old machine code, with the old predicate inside, and tests and
benchmarks would run code that is no longer in the tree.  Here every lfqt
kernel's stamp is that of the whole package (each source's path and a hash
of its contents), so that any edit recompiles them all, and a checkout that
leaves every file as it was (a branch switch and back, a revert) keeps the
cache, which a stamp of times would throw away.  The cache stays where numba
puts it (``NUMBA_CACHE_DIR``, else next to the sources, else the user's
cache directory); kernels outside lfqt are left alone.

Imported by ``lfqt/__init__.py`` before any kernel is defined.
"""
import hashlib
import os

from numba.core import caching

ROOT = os.path.dirname(os.path.abspath(__file__))


def tree_stamp(root=ROOT):
    """The stamp of every ``.py`` file under ``root``: relative path and a
    hash of the contents, in a fixed order (about 1 ms for lfqt)."""
    entries = []
    for dirpath, dirnames, files in os.walk(root):
        dirnames[:] = sorted(d for d in dirnames if d != "__pycache__")
        for name in sorted(f for f in files if f.endswith(".py")):
            path = os.path.join(dirpath, name)
            with open(path, "rb") as f:
                digest = hashlib.blake2b(f.read(), digest_size=16).hexdigest()
            entries.append((os.path.relpath(path, root), digest))
    return tuple(entries)


class _PackageStamp:
    """A locator mixin: lfqt's kernels only, stamped with the whole package."""
    _stamp = None

    def get_source_stamp(self):
        if _PackageStamp._stamp is None:  # once per process
            _PackageStamp._stamp = tree_stamp()
        return _PackageStamp._stamp

    @classmethod
    def from_function(cls, py_func, py_file):
        if not os.path.abspath(py_file).startswith(ROOT + os.sep):
            return None
        return super().from_function(py_func, py_file)


def _base(name):
    """numba's caching class ``name`` (the names lost their underscore in
    numba 0.59)."""
    return getattr(caching, name, None) or getattr(caching, "_" + name)


# One package-stamped variant of each source-file locator, in numba's order,
# ahead of numba's own.
PACKAGE_LOCATORS = [type("Package" + name, (_PackageStamp, _base(name)), {})
                    for name in ("UserProvidedCacheLocator", "InTreeCacheLocator",
                                 "UserWideCacheLocator")]
_classes = _base("CacheImpl")._locator_classes  # numba's locators, tried in order
if not any(issubclass(c, _PackageStamp) for c in _classes):
    _classes[:0] = PACKAGE_LOCATORS
