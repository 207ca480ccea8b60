"""Detectors on a live MAVLink link or a flight log: the map from messages to signals
(:mod:`.mavlink`), the monitor (:mod:`.monitor`) and the replay of ALFA flights as
MAVLink (:mod:`.replay`)."""
