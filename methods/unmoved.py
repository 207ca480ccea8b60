"""Channels not scored while a sensor they read has not moved since arming.

A sensor that reads the same value from the first grid step on (measured airspeed,
0 on every ALFA flight from 2018-09-11 on) is not measured: a model driven by its
constant scores nothing real. Whether it will ever move is not known during the flight,
so the rule is causal: a channel is not scored (its score NaN, never alarming) until
each sensor it depends on (:func:`skipped_channels`) has read a value other than its
first. The batch run (:func:`~alfa_bench.methods.run_detector`) and the live monitor
(:class:`alfa_bench.live.monitor.Monitor`) both apply it through
:class:`UnmovedSensors`, on the same grid values.
"""

from __future__ import annotations

import numpy as np

from alfa_bench.data import SIGNALS

__all__ = ["UnmovedSensors", "skipped_channels"]


def skipped_channels(detector, dead) -> dict[str, str]:
    """Channels of ``detector`` to skip when the signals ``dead`` are not measured: a
    channel scoring a dead output, and every channel when a dead signal is an input
    (no model is driven by a signal that is not there)."""
    return _skipped(detector.signals(), detector.channel_outputs(), detector.channels(),
                    dead)


def _skipped(signals, outputs, channels, dead) -> dict[str, str]:
    # a detector's layout read once by the caller: a nested selection builds its base
    # detector each time it is asked
    dead = [d for d in signals if d in set(dead)]
    if not dead:
        return {}
    inputs = [d for d in dead if d not in outputs]
    return {ch: (f"input {inputs[0]} not measured" if inputs else f"{out} not measured")
            for ch, out in zip(channels, outputs, strict=True)
            if inputs or out in dead}


class UnmovedSensors:
    """The sensors among ``detector``'s signals that have not moved since the first grid
    step fed (arming), and the channels they leave unscored.

    Parameters
    ----------
    detector : Detector
        Whose :meth:`~alfa_bench.methods.Detector.signals` are the columns fed.

    Feed the grid steps in order, in blocks of any size (:meth:`blanked`); a new flight
    or a re-armed link starts a new instance.
    """

    def __init__(self, detector):
        self.layout = (detector.signals(), detector.channel_outputs(), detector.channels())
        names, _, channels = self.layout
        self.sensors = [j for j, n in enumerate(names) if SIGNALS[n].kind == "sensor"]
        self.names = [names[j] for j in self.sensors]
        # sensor i leaves channel c unscored while it has not moved
        self.blocks = np.zeros((len(self.sensors), len(channels)), dtype=bool)
        for i, name in enumerate(self.names):
            for ch in _skipped(*self.layout, [name]):
                self.blocks[i, channels.index(ch)] = True
        self.first_: np.ndarray | None = None
        self.moved_ = np.zeros(len(self.sensors), dtype=bool)

    def blanked(self, x: np.ndarray) -> np.ndarray:
        """Which channels are not scored at the grid steps ``x`` (shape (n, signals),
        the steps after those fed before): shape (n, channels), bool."""
        x = np.atleast_2d(np.asarray(x, dtype=float))[:, self.sensors]
        if not x.shape[0]:
            return np.zeros((0, self.blocks.shape[1]), dtype=bool)
        if self.first_ is None:
            self.first_ = x[0].copy()
        moved = np.logical_or.accumulate(x != self.first_, axis=0) | self.moved_
        self.moved_ = moved[-1].copy()
        return (~moved).astype(np.int64) @ self.blocks.astype(np.int64) > 0

    def unmoved(self) -> list[str]:
        """The sensors that have not moved in the steps fed so far."""
        return [n for n, m in zip(self.names, self.moved_, strict=True) if not m]

    def skipped(self) -> dict[str, str]:
        """The channels left unscored at the last step fed, and why
        (:func:`skipped_channels` of :meth:`unmoved`)."""
        return _skipped(*self.layout, self.unmoved())
