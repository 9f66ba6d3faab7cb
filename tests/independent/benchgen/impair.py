"""Record-level impairments of a log: dropped and duplicated frames (or CSV rows), timestamp
jitter, timestamps that step back or jump forward. They act on what the logger wrote, after
the bench produced its samples; the order of records is kept (a step back stays a step back).
"""
import numpy as np

from .bench import STREAM_FRAMES


def impair_records(times, effects, seed):
    """Returns (index of each written record into the originals, its timestamp [s], stats)."""
    times = np.asarray(times, dtype=float)
    index = np.arange(len(times))
    stats = {"records_in": int(len(times))}
    drop = effects.get("dropped_frames")
    if drop:
        rng = np.random.default_rng([int(seed), STREAM_FRAMES, 0])
        keep = rng.random(len(index)) >= drop["rate"]
        stats["dropped"] = int(np.count_nonzero(~keep))
        index = index[keep]
    dup = effects.get("duplicated_frames")
    if dup:
        rng = np.random.default_rng([int(seed), STREAM_FRAMES, 1])
        twice = rng.random(len(index)) < dup["rate"]
        stats["duplicated"] = int(np.count_nonzero(twice))
        index = np.repeat(index, np.where(twice, 2, 1))
    written = times[index].copy()
    jitter = effects.get("timestamp_jitter")
    if jitter:
        rng = np.random.default_rng([int(seed), STREAM_FRAMES, 2])
        written += rng.normal(0.0, jitter["sigma"], len(written))
    for step in effects.all("timestamp_step"):
        later = times[index] >= step["at"]
        written[later] += step["by"]
        stats.setdefault("timestamp_steps", []).append(
            {"at_s": step["at"], "by_s": step["by"], "records_shifted": int(np.count_nonzero(later))})
    stats["records_out"] = int(len(index))
    stats["non_monotonic"] = int(np.count_nonzero(np.diff(written) < 0.0))
    return index, written, stats
