"""Flight logs as a corpus: a reader per format, each with its map from the log's
messages to the signal catalogue (:mod:`.tlog` MAVLink telemetry, :mod:`.dataflash`
ArduPilot DataFlash, :mod:`.ulog` PX4 ULog), and a folder of logs with a ``labels.csv``
turned into flights the workflow scores (:mod:`.corpus`). ``docs/own-flights.md``
tabulates the maps."""
