"""Damaged recordings for the tests: an MCAP file's chunks found by their records, cut, inverted
or dropped, and the shipped K&C dataset with one recording damaged."""

from __future__ import annotations

import shutil
from pathlib import Path

from elastokin.core.shipped import DATASET_DIR


def chunk_spans(data: bytes) -> list[tuple[int, int]]:
    """(start, end) byte offsets of each chunk record of an MCAP file (opcode 0x06: 1 + 8 + length
    bytes), up to the data section's end (opcode 0x0F)."""
    spans, at = [], 8
    while at + 9 <= len(data) and data[at] != 0x0F:
        end = at + 9 + int.from_bytes(data[at + 1:at + 9], "little")
        spans += [(at, end)] if data[at] == 0x06 else []
        at = end
    return spans


def damaged(source: Path, folder: Path, kind: str) -> Path:
    """``source`` damaged as ``kind`` says, written to ``folder/<kind>.mcap``: ``cut_half``,
    ``inverted`` (64 bytes inside a middle chunk's data), ``cut_last_byte``, ``cut_at_start``
    (1000 bytes into the first chunk)."""
    data = source.read_bytes()
    starts = [start for start, _ in chunk_spans(data)]
    middle, inside = len(data) // 2, starts[len(starts) // 2] + 2000
    out = {"cut_half": data[:middle], "inverted": data[:inside] + bytes(b ^ 0xFF for b in data[inside:inside + 64])
           + data[inside + 64:], "cut_last_byte": data[:-1], "cut_at_start": data[:starts[0] + 1000]}[kind]
    path = folder / f"{kind}.mcap"
    path.write_bytes(out)
    return path


def damaged_kc_dataset(folder: Path) -> Path:
    """The shipped K&C dataset copied into ``folder/kc``, bytes inverted inside the fourth of the
    six chunks of its roll recording (8.6 s of the roll test fail their CRC)."""
    shutil.copytree(DATASET_DIR / "kc", folder / "kc")
    roll = folder / "kc" / "02_kc_roll.mcap"
    damaged(roll, folder, "inverted").replace(roll)
    return folder / "kc"
