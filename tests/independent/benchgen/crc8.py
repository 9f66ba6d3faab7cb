"""CRC-8 SAE J1850: poly 0x1D, init 0xFF, no reflection, final xor 0xFF (check("123456789") = 0x4B).

docs/ARCHITECTURE.md §4: computed over data bytes 0..6 followed by the low byte of the CAN ID.
"""
import numpy as np

POLY, INIT, XOROUT = 0x1D, 0xFF, 0xFF


def _table():
    table = np.zeros(256, dtype=np.uint8)
    for byte in range(256):
        crc = byte
        for _ in range(8):
            crc = ((crc << 1) ^ POLY) & 0xFF if crc & 0x80 else (crc << 1) & 0xFF
        table[byte] = crc
    return table


TABLE = _table()


def crc8(data):
    """CRC of a bytes-like object."""
    crc = INIT
    for byte in bytes(data):
        crc = int(TABLE[crc ^ byte])
    return crc ^ XOROUT


def crc8_rows(rows):
    """CRC of every row of a (n, k) uint8 array, vectorised over rows."""
    rows = np.asarray(rows, dtype=np.uint8)
    crc = np.full(rows.shape[0], INIT, dtype=np.uint8)
    for column in range(rows.shape[1]):
        crc = TABLE[crc ^ rows[:, column]]
    return crc ^ np.uint8(XOROUT)


def frame_crc(data7, can_id):
    """docs/ARCHITECTURE.md §4 CRC for frames: rows of bytes 0..6, then the low byte of the CAN ID."""
    data7 = np.asarray(data7, dtype=np.uint8)
    id_column = np.full((data7.shape[0], 1), can_id & 0xFF, dtype=np.uint8)
    return crc8_rows(np.hstack([data7, id_column]))
