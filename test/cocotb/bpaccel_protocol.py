"""The stream protocol of docs/protocol.md, written plainly for the testbench:
the configuration from the emitted C headers, CELLS packets, reply decoding,
and the brute-force reference the device's pairs are checked against."""

import re
from dataclasses import dataclass, field
from pathlib import Path


def read_defines(*headers: Path) -> dict:
    """Every `#define NAME value` of the headers, numbers as int, strings unquoted."""
    out = {}
    for header in headers:
        for name, value in re.findall(r"^#define (\w+) (.+?)(?:\s*/\*.*)?$", header.read_text(), re.M):
            value = value.strip()
            if value.startswith('"'):
                out[name] = value.strip('"')
            else:
                out[name] = int(value.rstrip("u"), 0)
    return out


@dataclass(frozen=True)
class Config:
    """What the testbench needs of the configuration, from the headers EmitShell wrote."""
    defines: dict

    def __getattr__(self, name):
        key = "BPACCEL_SHELL_" + name.upper()
        if key in self.defines:
            return self.defines[key]
        return self.defines["BPACCEL_" + name.upper()]

    def reg(self, name: str) -> int:
        return self.defines[f"BPACCEL_SHELL_REG_{name}"]

    def field(self, reg: str, name: str, value: int) -> int:
        return (value & self.defines[f"BPACCEL_SHELL_REG_{reg}_{name}_MASK"]) >> self.defines[f"BPACCEL_SHELL_REG_{reg}_{name}_SHIFT"]

    def error(self, name: str) -> int:
        return self.defines[f"BPACCEL_SHELL_ERR_{name}"]

    @staticmethod
    def load(verilog_dir: Path) -> "Config":
        return Config(read_defines(verilog_dir / "bpaccel_shell.h", verilog_dir / "bpaccel_params.h"))


Box = tuple  # ((min x, y, z), (max x, y, z)) of integer keys


def overlaps(a: Box, b: Box) -> bool:
    return all(a[0][k] <= b[1][k] and b[0][k] <= a[1][k] for k in range(3))


def brute_force_pairs(boxes: list, split: int = 0) -> set:
    """Every overlapping pair i < j of one cell; with a split, only i < split <= j."""
    return {(i, j) for i in range(len(boxes)) for j in range(i + 1, len(boxes))
            if (split == 0 or i < split <= j) and overlaps(boxes[i], boxes[j])}


def issue_cycles(n: int, m: int, split: int = 0) -> int:
    """The core's schedule length (docs/microarchitecture.md): C(n, m), or a bipartite run's."""
    if n < 2:
        return 0
    if split == 0:
        return sum(n - 1 - b * m for b in range((n - 2) // m + 1))
    return sum(min(n - 1 - b * m, 2 * m - 1 + n - split) for b in range((split - 1) // m + 1))


def box_words(cfg: Config, box: Box) -> list:
    keys = list(box[0]) + list(box[1])
    if cfg.box_words == 6:
        return keys
    return [keys[2 * i] | keys[2 * i + 1] << 16 for i in range(3)]


@dataclass
class Cell:
    boxes: list
    split: int = 0
    count: int = None  # the header's count, when a test lies about it

    def header(self) -> list:
        return [len(self.boxes) if self.count is None else self.count, self.split]


def cells_words(cfg: Config, cells: list, cell_count: int = None, header: int = None) -> list:
    """The words of a CELLS command (before padding)."""
    words = [header if header is not None else (cfg.op_cells | cfg.protocol_version << 8),
             len(cells) if cell_count is None else cell_count]
    for cell in cells:
        words += cell.header()
        for box in cell.boxes:
            words += box_words(cfg, box)
    return words


def to_packet(cfg: Config, words: list) -> bytes:
    """Words padded with zeros to whole beats, little endian."""
    k = cfg.words_per_beat
    words = words + [0] * (-len(words) % k)
    return b"".join(w.to_bytes(4, "little") for w in words)


@dataclass
class Reply:
    records: list            # CELLS: (cell, i, j) of every set mask bit, in arrival order
    record_count: int        # records in the reply
    trailer: dict = field(default_factory=dict)
    fill_words: list = field(default_factory=list)  # the words between the records and the trailer

    @property
    def error(self) -> int:
        return self.trailer["HEADER"] >> 8 & 0xFF


TRAILER_FIELDS = ("HEADER", "DETAIL", "RECORDS", "BOXES", "DEVICE_CYCLES", "STALL_CYCLES", "ISSUE_CYCLES",
                  "PAIRS", "INTAKE_CYCLES", "CELLS", "RESERVED")


def decode_reply(cfg: Config, data: bytes) -> Reply:
    """A reply as the host reads it: the trailer at the end, records from the start up to its count."""
    words = [int.from_bytes(data[i:i + 4], "little") for i in range(0, len(data), 4)]
    k = cfg.words_per_beat
    assert len(words) % k == 0, f"a reply of {len(words)} words is not whole beats of {k}"
    assert len(words) >= cfg.trailer_words, "a reply shorter than its trailer"
    tw = words[-cfg.trailer_words:]
    trailer = {}
    for name in TRAILER_FIELDS:
        at = cfg.defines[f"BPACCEL_SHELL_TRAILER_{name}"]
        wide = name.endswith("_CYCLES") or name == "PAIRS"
        trailer[name] = tw[at] | (tw[at + 1] << 32 if wide else 0)
    assert trailer["HEADER"] >> 24 == cfg.trailer_magic, f"trailer magic {trailer['HEADER']:#x}"
    body = words[:-cfg.trailer_words]
    n = trailer["RECORDS"]
    rw = cfg.record_words
    assert len(body) == -(-n * rw // k) * k, f"{len(body)} words before the trailer for {n} records of {rw} words"
    wrap = (1 << cfg.index_width) - 1
    records = []
    for r in range(n):
        w = body[r * rw:(r + 1) * rw]
        if cfg.index_words == 1:
            i_base, j_base, rest = w[0] & 0xFFFF, w[0] >> 16, w[1:]
        else:
            i_base, j_base, rest = w[0], w[1], w[2:]
        cell, mask_words = rest[0], rest[1:]
        mask = sum(m << (32 * q) for q, m in enumerate(mask_words))
        assert mask != 0, "a record without a hit"
        assert mask >> cfg.m == 0, "a mask bit above the lanes"
        for lane in range(cfg.m):
            if mask >> lane & 1:
                records.append((cell, (i_base + lane) & wrap, (j_base + lane) & wrap))
    return Reply(records, n, trailer, body[n * rw:])
