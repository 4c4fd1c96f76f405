"""Copy the dashboard's JavaScript libraries from the npm registry into the package.

    python scripts/vendor_js.py           # fetch the pinned versions with `npm pack`, copy files
    python scripts/vendor_js.py --check   # verify the committed files against vendor.json (offline)

The dashboard serves these files itself, so it works offline and on machines without npm: the
copied files are committed under ``robotale/webapp/static/vendor/<package>/`` together with
each package's licence, and ``vendor.json`` records every package's version, the registry's
integrity hash of its tarball and the sha256 of every copied file. The full plotly.js is not
vendored (the plotly Python package ships it and the app serves that copy), only two of its
partial bundles, of the same version, that draw the perspectives' figures with a third of the
script to parse: cartesian (scatter, bar, box) and gl3d (scatter3d).

To upgrade a library, change its version below, run the script, look at the dashboard, commit.
"""

from __future__ import annotations

import argparse
import hashlib
import json
import shutil
import subprocess
import sys
import tarfile
import tempfile
from dataclasses import dataclass
from pathlib import Path

VENDOR = Path(__file__).resolve().parent.parent / "robotale" / "webapp" / "static" / "vendor"
MANIFEST = VENDOR / "vendor.json"


@dataclass(frozen=True)
class Package:
    name: str
    version: str
    #: file in the package tarball -> file name under vendor/<folder>/
    files: dict[str, str]

    @property
    def folder(self) -> str:
        return self.name.replace("@", "").replace("/", "-")


PACKAGES = (
    Package(
        "cytoscape",
        "3.34.4",
        {"dist/cytoscape.min.js": "cytoscape.min.js", "LICENSE": "LICENSE"},
    ),
    # cytoscape-dagre 4 bundles @dagrejs/dagre, the maintained dagre: one file, layered layout.
    Package(
        "cytoscape-dagre",
        "4.0.1",
        {"dist/cytoscape-dagre.min.js": "cytoscape-dagre.min.js", "LICENSE": "LICENSE"},
    ),
    Package(
        "bpmn-js",
        "18.31.1",
        {
            "dist/bpmn-navigated-viewer.production.min.js": "bpmn-navigated-viewer.min.js",
            "dist/assets/diagram-js.css": "diagram-js.css",
            "dist/assets/bpmn-js.css": "bpmn-js.css",
            "LICENSE": "LICENSE",
        },
    ),
    # Partial bundles of the plotly.js inside the plotly Python package, which writes the figures.
    *(
        Package(
            f"plotly.js-{part}-dist-min",
            "4.1.1",
            {f"plotly-{part}.min.js": f"plotly-{part}.min.js", "LICENSE": "LICENSE"},
        )
        for part in ("cartesian", "gl3d")
    ),
)


def sha256(path: Path) -> str:
    return hashlib.sha256(path.read_bytes()).hexdigest()


def pack(package: Package, into: Path) -> tuple[Path, str]:
    """Download ``package`` with ``npm pack``; the tarball and its registry integrity."""
    spec = f"{package.name}@{package.version}"
    result = subprocess.run(
        ["npm", "pack", spec, "--json", "--pack-destination", str(into)],
        capture_output=True,
        text=True,
        check=False,
    )
    if result.returncode != 0:
        sys.exit(f"npm pack {spec} failed:\n{result.stderr.strip()}")
    info = json.loads(result.stdout)[0]
    return into / info["filename"], info["integrity"]


def extract(tarball: Path, package: Package, into: Path) -> dict[str, str]:
    """Copy the package's listed files into ``into``; their sha256 by file name."""
    into.mkdir(parents=True, exist_ok=True)
    copied = {}
    with tarfile.open(tarball) as archive:
        for inside, name in package.files.items():
            member = archive.extractfile(f"package/{inside}")
            if member is None:
                sys.exit(f"{package.name}@{package.version} has no file {inside}.")
            target = into / name
            target.write_bytes(member.read())
            copied[name] = sha256(target)
    return copied


def vendor() -> None:
    manifest = {}
    with tempfile.TemporaryDirectory() as scratch:
        for package in PACKAGES:
            tarball, integrity = pack(package, Path(scratch))
            folder = VENDOR / package.folder
            shutil.rmtree(folder, ignore_errors=True)
            files = extract(tarball, package, folder)
            manifest[package.name] = {
                "version": package.version,
                "integrity": integrity,
                "folder": package.folder,
                "files": files,
            }
            print(f"{package.name}@{package.version}: {', '.join(files)}")
    MANIFEST.write_text(json.dumps(manifest, indent=2) + "\n")


def check() -> list[str]:
    """What differs between the committed files, ``vendor.json`` and :data:`PACKAGES`."""
    manifest = json.loads(MANIFEST.read_text())
    problems = []
    if set(manifest) != {p.name for p in PACKAGES}:
        problems.append(
            f"vendor.json lists {sorted(manifest)}, the script {[p.name for p in PACKAGES]}"
        )
    for package in PACKAGES:
        entry = manifest.get(package.name, {})
        if entry.get("version") != package.version:
            problems.append(
                f"{package.name}: vendor.json has {entry.get('version')}, want {package.version}"
            )
        for name, digest in entry.get("files", {}).items():
            path = VENDOR / package.folder / name
            if not path.is_file() or sha256(path) != digest:
                problems.append(f"{path.relative_to(VENDOR)} is missing or changed")
        if set(entry.get("files", {})) != set(package.files.values()):
            problems.append(f"{package.name}: vendor.json lists other files than the script")
    return problems


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--check", action="store_true", help="verify, do not download")
    if parser.parse_args().check:
        problems = check()
        for problem in problems:
            print(problem, file=sys.stderr)
        return 1 if problems else 0
    vendor()
    return 0


if __name__ == "__main__":
    sys.exit(main())
