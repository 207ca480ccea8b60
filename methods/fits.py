r"""Fits kept in a process, keyed by the code, hyper-parameters and data that made them.

A fit is deterministic: the same detector code with the same hyper-parameters, fitted
on the same data, learns the same. Nested selection asks for the same fits again and
again (the out-of-sample maxima of its inner fit without date :math:`d` and of the one
without :math:`e` both need the model without :math:`\{d, e\}`, and later scored
dates' folds need the inner fits again), so fits are kept under a key of exactly those
three (:func:`fit_key`):

- the code: the class's module, qualified name and a digest of its source and of its
  bases' (:func:`~.base.source_digest`), so that a class of the same name in another
  module, or one redefined in a notebook, is another key;
- the hyper-parameters, as JSON: only plain data (:func:`plain_data`), since an
  estimator object may change after the fit;
- the data: the digest of every segment fitted on (:func:`~.base.segment_digest`), or
  any other JSON-ready description of it that names it exactly.

A key is a digest of a JSON document of those, so that it can name a fit outside the
process too. Each store (:class:`KeptFits`) keeps the fits last used, up to its bound:
:data:`MODEL_FITS` the models :func:`kept_fit` fits, and
:data:`~.nested_selection.INNER_FITS` a nested selection's inner fits. Within
:func:`fresh_fits` every store starts empty, and is given back its fits after: the
contract's refit check fits anew, so that a fit which is not deterministic cannot hide
behind one kept before.
"""

from __future__ import annotations

import functools
import hashlib
import json
import weakref
from collections import OrderedDict
from collections.abc import Iterator
from contextlib import contextmanager

from .base import Detector, segment_digest, source_digest

__all__ = ["MODEL_FITS", "KeptFits", "code_of", "fit_key", "fresh_fits", "kept_fit",
           "plain_data", "segments_data"]


def plain_data(value) -> bool:
    """Whether ``value`` is data alone (numbers, strings, None, and lists, tuples and
    string-keyed dicts of them), which JSON writes whole."""
    if value is None or isinstance(value, str | int | float | bool):
        return True
    if isinstance(value, list | tuple):
        return all(map(plain_data, value))
    if isinstance(value, dict):
        return all(isinstance(k, str) and plain_data(v) for k, v in value.items())
    return False


@functools.cache
def code_of(cls: type) -> dict[str, str]:
    """What names the code of ``cls``: its module, qualified name and the digest of its
    source and its bases', alfa-bench's included (read once per class: a class object
    runs the code it was made from, whatever its file says later)."""
    return {"module": cls.__module__, "class": cls.__qualname__,
            "source": source_digest(cls, package=True)}


def segments_data(segments: list) -> list[str]:
    """The data of ``segments`` as a key names it: each one's
    :func:`~.base.segment_digest`, in order."""
    return [segment_digest(s).hex() for s in segments]


def fit_key(detector: Detector, data, params: dict | None = None) -> str | None:
    """The key of a fit of ``detector``'s code with ``params`` (default: all its
    hyper-parameters) on ``data`` (JSON-ready, such as :func:`segments_data`); None
    where the hyper-parameters are not plain data (such a fit is not kept)."""
    params = detector.get_params() if params is None else params
    if not plain_data(params):
        return None
    document = {**code_of(type(detector)), "params": params, "data": data}
    return hashlib.blake2b(json.dumps(document, sort_keys=True).encode(),
                           digest_size=16).hexdigest()


class KeptFits:
    """Fits by their key (:func:`fit_key`), the ``kept`` last used.

    Parameters
    ----------
    kept : int
        How many fits are kept; the least recently used goes first.
    """

    def __init__(self, kept: int):
        self.kept = kept
        self._fits: OrderedDict[str, object] = OrderedDict()
        _STORES.add(self)

    def __len__(self) -> int:
        return len(self._fits)

    def get(self, key: str | None):
        """The fit kept under ``key``, now the last used; None where there is none (or
        ``key`` is None)."""
        if key is None or key not in self._fits:
            return None
        self._fits.move_to_end(key)
        return self._fits[key]

    def put(self, key: str | None, fit) -> None:
        """Keep ``fit`` under ``key`` (not where ``key`` is None), dropping the least
        recently used beyond :attr:`kept`."""
        if key is None:
            return
        self._fits[key] = fit
        self._fits.move_to_end(key)
        while len(self._fits) > self.kept:
            self._fits.popitem(last=False)

    def clear(self) -> None:
        """Forget every fit."""
        self._fits.clear()


#: every store, for :func:`fresh_fits`
_STORES: weakref.WeakSet[KeptFits] = weakref.WeakSet()


@contextmanager
def fresh_fits() -> Iterator[None]:
    """Within it, every :class:`KeptFits` starts empty, so that a fit is made anew, not
    taken from one made before; the fits made within may serve each other, as in any
    fit. After it, each store holds what it held before, and none made within."""
    held = [(store, store._fits) for store in list(_STORES)]
    for store, _ in held:
        store._fits = OrderedDict()
    try:
        yield
    finally:
        for store, fits in held:
            store._fits = fits


#: the models :func:`kept_fit` fitted in this process, each as the attributes its fit
#: set: the 256 last used
MODEL_FITS = KeptFits(256)


def kept_fit(detector: Detector, segments: list, fit, state: tuple[str, ...]) -> None:
    """``fit(segments)``, which sets ``detector``'s learned attributes ``state``, or
    those attributes as a fit of the same code with the same hyper-parameters (the
    threshold's aside: :attr:`~.base.Detector.threshold_params`) on the same data left
    them, kept in :data:`MODEL_FITS`.

    Only a detector whose hyper-parameters are plain data (:func:`plain_data`) is kept.
    A kept fit is restored in the order the fit set its attributes, as the fit token
    (:func:`~.base.fit_token`) digests them in order."""
    params = {k: v for k, v in detector.get_params().items()
              if k not in detector.threshold_params}
    key = fit_key(detector, segments_data(segments), params)
    kept = MODEL_FITS.get(key)
    if kept is not None:
        detector.__dict__.update(kept)
        return
    fit(segments)
    MODEL_FITS.put(key, {n: v for n, v in vars(detector).items() if n in state})
