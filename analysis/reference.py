"""Published results quoted beside ours (never computed, never used for fitting).

Keipour, Mousaei, Scherer, "Automatic Real-time Anomaly Detection for Autonomous
Aerial Vehicles", ICRA 2019, Table I and Sec. V-C, on 22 ALFA flights. The counts
follow from the text: 2 FP and 2 FN, one flight with both, 19 flights correct.
"""

__all__ = ["ICRA2019_BY_FAULT", "ICRA2019_SUMMARY", "ICRA2019_NAME"]

ICRA2019_NAME = "Keipour et al. ICRA 2019 (paper)"

ICRA2019_SUMMARY = {
    "flights": 22, "tp": 15, "fp": 2, "fn": 2, "tn": 4,
    "precision": 0.8823, "recall": 0.8823, "accuracy": 0.8636,
    "mean_detection_s": 2.02, "max_detection_s": 5.6,
}

# fault class -> (flights, flight time s, mean detection s, max detection s, accuracy)
ICRA2019_BY_FAULT = {
    "engine": (7, 665, 2.28, 3.37, 1.00),
    "rudder": (3, 171, 0.21, 0.25, None),
    "elevator": (2, 181, 0.36, 0.36, None),
    "aileron": (4, 340, 3.31, 5.6, None),
    "rudder+aileron": (1, 116, 3.48, 3.48, None),
    "none": (5, 262, None, None, None),
    "total": (22, 1735, 2.02, 5.6, 0.8636),
}
