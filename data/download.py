"""Find the ALFA data, or download the official archive and verify it.

The data is looked up in this order: the ``ALFA_DIR`` environment variable, the
workflow's ``alfa_dir`` setting; either names the folder that holds
``processed/``. Without one, the workflow downloads the processed flights from
CMU KiltHub (DOI 10.1184/R1/12707963). KiltHub is a figshare repository: its
public API lists each file of the article with its download address, its size
and the MD5 the repository computed on upload. The download is checked against
both, and against a SHA-256 pinned in the config where one is given, before it is
unpacked.
"""

from __future__ import annotations

import hashlib
import json
import logging
import os
import shutil
import tarfile
import urllib.request
import zipfile
from pathlib import Path, PurePosixPath

from .errors import AlfaDataError

__all__ = ["download_archive", "fetch_alfa", "processed_dir", "resolve_alfa_dir", "unpack"]

log = logging.getLogger("alfa_bench.data")

_TIMEOUT_S = 60
_CHUNK = 1 << 20


def resolve_alfa_dir(configured: str | os.PathLike | None = None) -> Path | None:
    """The ALFA folder from ``ALFA_DIR``, else ``configured``, else None."""
    value = os.environ.get("ALFA_DIR") or configured
    return Path(value) if value else None


def processed_dir(alfa_dir: str | os.PathLike) -> Path:
    """``alfa_dir/processed``, checked to exist."""
    processed = Path(alfa_dir) / "processed"
    if not processed.is_dir():
        raise AlfaDataError(f"{processed} does not exist: ALFA_DIR (or alfa_dir in the "
                            "config) must name the folder that holds processed/")
    return processed


def _open(url: str):
    request = urllib.request.Request(url, headers={"User-Agent": "alfa-bench"})
    return urllib.request.urlopen(request, timeout=_TIMEOUT_S)


def download_archive(api_url: str, filename: str, dest: Path,
                     sha256: str | None = None) -> Path:
    """Download ``filename`` of the figshare article at ``api_url`` into ``dest``.

    Raises
    ------
    AlfaDataError
        If the article has no such file, or the download's size, MD5 or SHA-256
        differ from what the repository (or the config) states.
    """
    with _open(api_url) as response:
        listing = json.load(response)
    entry = next((f for f in listing if f.get("name") == filename), None)
    if entry is None:
        names = ", ".join(sorted(str(f.get("name")) for f in listing))
        raise AlfaDataError(f"the archive lists no file {filename!r} (it has: {names})")

    dest.mkdir(parents=True, exist_ok=True)
    target = dest / filename
    part = target.with_name(target.name + ".part")
    md5, sha = hashlib.md5(), hashlib.sha256()
    size = 0
    log.info("downloading %s (%s bytes) from %s", filename, entry.get("size"),
             entry["download_url"])
    with _open(entry["download_url"]) as response, part.open("wb") as out:
        while chunk := response.read(_CHUNK):
            out.write(chunk)
            md5.update(chunk)
            sha.update(chunk)
            size += len(chunk)
    checks = [("size", size, entry.get("size")),
              ("MD5", md5.hexdigest(), entry.get("computed_md5")),
              ("SHA-256", sha.hexdigest(), sha256)]
    for what, got, expected in checks:
        if expected is not None and got != expected:
            part.unlink()
            raise AlfaDataError(f"download of {filename} failed verification: {what} is "
                                f"{got}, expected {expected}")
    part.replace(target)
    log.info("verified %s: %d bytes, md5 %s, sha256 %s", filename, size, md5.hexdigest(),
             sha.hexdigest())
    return target


def _members(archive: Path) -> list[str]:
    if zipfile.is_zipfile(archive):
        with zipfile.ZipFile(archive) as z:
            return z.namelist()
    if tarfile.is_tarfile(archive):
        with tarfile.open(archive) as t:
            return t.getnames()
    raise AlfaDataError(f"{archive} is neither a zip nor a tar archive")


def unpack(archive: Path, dest: Path) -> Path:
    """Unpack ``archive`` safely so that its flights land in ``dest/processed``.

    The archive may hold a ``processed/`` folder at any depth, or the flight
    folders at its top level. Returns ``dest``.
    """
    names = _members(archive)
    for name in names:
        p = PurePosixPath(name)
        if p.is_absolute() or ".." in p.parts:
            raise AlfaDataError(f"{archive} holds an unsafe path {name!r}; not unpacked")
    parts = [PurePosixPath(n).parts for n in names]
    holder = next((q[:q.index("processed")] for q in parts if "processed" in q[:-1]), None)
    staging = dest / ".unpacking"
    if staging.exists():
        shutil.rmtree(staging)
    staging.mkdir(parents=True)
    if zipfile.is_zipfile(archive):
        with zipfile.ZipFile(archive) as z:
            z.extractall(staging)
    else:
        with tarfile.open(archive) as t:
            t.extractall(staging, filter="data")
    found = staging.joinpath(*holder, "processed") if holder is not None else staging
    target = dest / "processed"
    if target.exists():
        shutil.rmtree(target)
    found.rename(target)
    shutil.rmtree(staging, ignore_errors=True)
    processed_dir(dest)
    return dest


def fetch_alfa(api_url: str, filename: str, dest: str | os.PathLike,
               sha256: str | None = None) -> Path:
    """Download, verify and unpack the ALFA archive; return the ALFA folder."""
    dest = Path(dest)
    archive = download_archive(api_url, filename, dest, sha256)
    return unpack(archive, dest)
