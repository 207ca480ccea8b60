"""Find the ALFA data, or download the official archive and verify it.

The data is looked up in this order: the ``ALFA_DIR`` environment variable, the
workflow's ``alfa_dir`` setting; either names the folder that holds
``processed/``. Without one, the workflow downloads the processed flights from
CMU KiltHub (DOI 10.1184/R1/12707963). KiltHub is a figshare repository: its
public API lists each file of the article with its download address, its size
and the MD5 the repository computed on upload. The download is checked against
both, and against the MD5 and SHA-256 pinned in the config, before it is unpacked.

The archive holds, per flight, the CSVs, the ROS bag and a MATLAB file. Only the
CSVs are extracted: the pipeline reads nothing else, and the rest is most of the
archive's size.
"""

from __future__ import annotations

import hashlib
import http.client
import json
import logging
import os
import shutil
import tarfile
import urllib.error
import urllib.request
import zipfile
from pathlib import Path, PurePosixPath

from .errors import DownloadError, MissingFolderError

__all__ = ["ARTICLE_URL", "download_archive", "fetch_alfa", "processed_dir", "resolve_alfa_dir",
           "unpack"]

log = logging.getLogger("alfa_bench.data")

#: Where a person can fetch the archive by hand when the workflow cannot.
ARTICLE_URL = "https://doi.org/10.1184/R1/12707963"

_TIMEOUT_S = 60
_CHUNK = 1 << 20
_BY_HAND = (f"or download it by hand from {ARTICLE_URL}, unpack it, and set ALFA_DIR to "
            "the folder that holds processed/")


def resolve_alfa_dir(configured: str | os.PathLike | None = None) -> Path | None:
    """The ALFA folder from ``ALFA_DIR``, else ``configured``, else None."""
    value = os.environ.get("ALFA_DIR") or configured
    return Path(value) if value else None


def processed_dir(alfa_dir: str | os.PathLike,
                  source: str = "ALFA_DIR (or alfa_dir in the config)") -> Path:
    """``alfa_dir/processed``, checked to exist; ``source`` is what named ``alfa_dir``,
    for the error."""
    processed = Path(alfa_dir) / "processed"
    if not processed.is_dir():
        raise MissingFolderError(f"{processed} does not exist: {source} must name the "
                                 "folder that holds ALFA's processed/")
    return processed


def _open(url: str):
    request = urllib.request.Request(url, headers={"User-Agent": "alfa-bench"})
    try:
        return urllib.request.urlopen(request, timeout=_TIMEOUT_S)
    except (TimeoutError, urllib.error.URLError, ConnectionError) as e:
        reason = getattr(e, "reason", e)
        raise DownloadError(f"cannot reach {url} ({reason}). Check the network and run "
                            f"again, {_BY_HAND}") from e


def _digests(path: Path) -> tuple[int, str, str]:
    md5, sha = hashlib.md5(), hashlib.sha256()
    with path.open("rb") as f:
        while chunk := f.read(_CHUNK):
            md5.update(chunk)
            sha.update(chunk)
    return path.stat().st_size, md5.hexdigest(), sha.hexdigest()


def _mismatch(filename: str, got: tuple[int, str, str], size: int | None,
              md5s: list[tuple[str, str | None]], sha256: str | None) -> str | None:
    """Why a file with ``got`` = (size, MD5, SHA-256) is not the archive, or None."""
    if size is not None and got[0] != size:
        return (f"the download of {filename} stopped at {got[0]:,} of {size:,} bytes "
                "(the connection broke). Run again")
    for source, md5 in md5s:
        if md5 is not None and got[1] != md5:
            return (f"{filename} failed verification: its MD5 is {got[1]}, {source} says "
                    f"{md5}. The file is damaged or not the official archive. Run again; "
                    "if it persists, the archive was changed upstream: check it and update "
                    "download.md5 in the config")
    if sha256 is not None and got[2] != sha256:
        return (f"{filename} failed verification: its SHA-256 is {got[2]}, the config pins "
                f"{sha256}. Run again, or update download.sha256 in the config")
    return None


def download_archive(api_url: str, filename: str, dest: Path, md5: str | None = None,
                     sha256: str | None = None) -> Path:
    """Download ``filename`` of the figshare article at ``api_url`` into ``dest``.

    A file already there that passes every check is kept, so a run stopped while
    unpacking does not download again.

    Parameters
    ----------
    api_url : str
        The article's file listing (figshare API v2).
    filename : str
        The file to fetch, as the listing names it.
    dest : Path
        Folder to download into.
    md5, sha256 : str, optional
        Digests pinned in the config, checked besides the repository's MD5 and size.

    Raises
    ------
    DownloadError
        If the network cannot be reached, the article has no such file, or the
        download's size, MD5 or SHA-256 differ from what is stated. The message says
        what to do; a file that fails is removed.
    """
    with _open(api_url) as response:
        listing = json.load(response)
    entry = next((f for f in listing if f.get("name") == filename), None)
    if entry is None:
        names = ", ".join(sorted(str(f.get("name")) for f in listing))
        raise DownloadError(f"the archive lists no file {filename!r} (it has: {names}); "
                            "set download.file in the config to the processed flights' "
                            "archive")
    size = entry.get("size")
    md5s = [("the repository", entry.get("computed_md5")), ("the config", md5)]
    dest.mkdir(parents=True, exist_ok=True)
    target = dest / filename
    if target.exists() and _mismatch(filename, _digests(target), size, md5s, sha256) is None:
        log.info("%s is already here and verified; not downloaded again", target)
        return target

    part = target.with_name(target.name + ".part")
    log.info("downloading %s (%s bytes) from %s", filename, size, entry["download_url"])
    done, shown = 0, -1
    try:
        with _open(entry["download_url"]) as response, part.open("wb") as out:
            while chunk := response.read(_CHUNK):
                out.write(chunk)
                done += len(chunk)
                tenth = done * 10 // size if size else -1
                if tenth > shown:
                    shown = tenth
                    log.info("downloaded %d of %s MB", done >> 20,
                             size >> 20 if size else "?")
    except (OSError, http.client.HTTPException) as e:
        part.unlink(missing_ok=True)
        raise DownloadError(f"the download of {filename} broke off after {done:,} bytes "
                            f"({e}). Run again, {_BY_HAND}") from e
    got = _digests(part)
    why = _mismatch(filename, got, size, md5s, sha256)
    if why is not None:
        part.unlink()
        raise DownloadError(f"{why} (the partial file was removed), {_BY_HAND}")
    part.replace(target)
    log.info("verified %s: %d bytes, md5 %s, sha256 %s", filename, *got)
    return target


def _members(archive: Path) -> list[str]:
    if zipfile.is_zipfile(archive):
        with zipfile.ZipFile(archive) as z:
            return z.namelist()
    if tarfile.is_tarfile(archive):
        with tarfile.open(archive) as t:
            return t.getnames()
    raise DownloadError(f"{archive} is neither a zip nor a tar archive; remove it and run "
                        f"again, {_BY_HAND}")


def _extract_csvs(archive: Path, names: list[str], dest: Path) -> None:
    csvs = [n for n in names if n.lower().endswith(".csv")]
    log.info("extracting %d CSVs of %d files in %s", len(csvs), len(names), archive.name)
    if zipfile.is_zipfile(archive):
        with zipfile.ZipFile(archive) as z:
            for i, name in enumerate(csvs, 1):
                z.extract(name, dest)
                if i % 500 == 0:
                    log.info("extracted %d of %d CSVs", i, len(csvs))
    else:
        with tarfile.open(archive) as t:
            t.extractall(dest, members=[t.getmember(n) for n in csvs], filter="data")


def unpack(archive: Path, dest: Path) -> Path:
    """Extract the CSVs of ``archive`` safely so that its flights land in
    ``dest/processed``.

    The archive may hold a ``processed/`` folder at any depth, or the flight
    folders at its top level. Returns ``dest``.
    """
    names = _members(archive)
    for name in names:
        p = PurePosixPath(name)
        if p.is_absolute() or ".." in p.parts:
            raise DownloadError(f"{archive} holds an unsafe path {name!r}; not unpacked")
    parts = [PurePosixPath(n).parts for n in names]
    holder = next((q[:q.index("processed")] for q in parts if "processed" in q[:-1]), None)
    staging = dest / ".unpacking"
    if staging.exists():
        shutil.rmtree(staging)
    staging.mkdir(parents=True)
    _extract_csvs(archive, names, staging)
    found = staging.joinpath(*holder, "processed") if holder is not None else staging
    target = dest / "processed"
    if target.exists():
        shutil.rmtree(target)
    found.rename(target)
    shutil.rmtree(staging, ignore_errors=True)
    processed_dir(dest)
    return dest


def fetch_alfa(api_url: str, filename: str, dest: str | os.PathLike, md5: str | None = None,
               sha256: str | None = None) -> Path:
    """Download, verify and unpack the ALFA archive; return the ALFA folder."""
    dest = Path(dest)
    archive = download_archive(api_url, filename, dest, md5, sha256)
    return unpack(archive, dest)
