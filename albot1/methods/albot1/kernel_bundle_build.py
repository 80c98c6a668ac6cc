"""Build the kernel bundle of a wheel: ``python -m albot1.methods.albot1.kernel_bundle_build DEST`` (``setup.py``).

Compiles every kernel of Albot1 and of its places layer on its warm-up
samples (the argument types the mappers call them with) and copies numba's
cache files into ``DEST`` (:mod:`.kernel_bundle` explains what is checked
where they are used). Run by the build step with ``XDG_CACHE_HOME`` set to
an empty folder, so that what is copied is what this build compiled; a
module of its own, imported by no other, because it needs every kernel
set, and the warm-up (which reads the bundle) is imported by the mappers.
"""

from __future__ import annotations

import json
import shutil
import sys
from pathlib import Path

from albot1.methods.albot1 import compiled, kernel_bundle, warm_up
from albot1.methods.albot1.mapping.kernel_set import MappingKernels
from albot1.methods.albot1.perception.kernels import PerceptionKernels
from albot1.methods.albot1.places.kernels import PlacesKernels


def build(dest: Path) -> int:
    """Compile every kernel (or load this code version's cache) and copy numba's files to ``dest``: file count."""
    warm_up.warm_up((PerceptionKernels(), MappingKernels(), PlacesKernels()))
    if dest.exists():
        shutil.rmtree(dest)
    files: dict[str, str] = {}
    for folder in sorted({p.parent for p in kernel_bundle.PACKAGE_DIR.rglob("*.py")}):
        cached = compiled.CACHE_DIR / kernel_bundle.cache_subfolder(folder)
        if not cached.is_dir():
            continue
        relative = folder.relative_to(kernel_bundle.PACKAGE_DIR).as_posix()
        for path in sorted(cached.iterdir()):
            if path.suffix in kernel_bundle.SUFFIXES:
                (dest / relative).mkdir(parents=True, exist_ok=True)
                shutil.copyfile(path, dest / relative / path.name)
                files[f"{relative}/{path.name}"] = kernel_bundle.sha256(path)
    manifest = {**kernel_bundle.fingerprint(), "files": files}
    dest.mkdir(parents=True, exist_ok=True)
    (dest / kernel_bundle.MANIFEST).write_text(json.dumps(manifest, indent=1, sort_keys=True) + "\n", encoding="utf-8")
    return len(files)


def main(argv: list[str]) -> int:
    if len(argv) != 1:
        sys.stderr.write("usage: python -m albot1.methods.albot1.kernel_bundle_build DEST\n")
        return 2
    count = build(Path(argv[0]))
    sys.stdout.write(f"kernel bundle: {count} numba cache files in {argv[0]}\n")
    return 0


if __name__ == "__main__":
    raise SystemExit(main(sys.argv[1:]))
