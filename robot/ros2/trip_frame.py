"""trip framing (docs/trip-protocol.md), as sim/frame.c has it.

A frame is STX payload ETX; inside, STX, ETX and DLE go as DLE, byte ^ 0x40.
The parser takes bytes as they come and answers whole payloads and the
framing errors, each error once, as the simulator's does.
"""

STX, ETX, DLE = 2, 3, 16
SPECIAL = (STX, ETX, DLE)
BLANK = (13, 10, 32, 9)

ERROR_TEXT = {
    "stray": "framing byte outside a frame",
    "interrupted": "framing frame interrupted by STX",
    "escape": "framing bad escape after DLE",
    "too-long": "too-long frame over the size limit",
}


def encode(payload):
    """The frame of payload (bytes or str)."""
    if isinstance(payload, str):
        payload = payload.encode()
    out = bytearray([STX])
    for b in payload:
        if b in SPECIAL:
            out += bytes([DLE, b ^ 0x40])
        else:
            out.append(b)
    out.append(ETX)
    return bytes(out)


class Parser:
    """Bytes in, events out: ("frame", payload) or ("error", code)."""

    OUTSIDE, JUNK, INSIDE, ESCAPED, SKIPPING = range(5)

    def __init__(self, limit=1024):
        self.limit = limit
        self.state = self.OUTSIDE
        self.buf = bytearray()

    def pending(self):
        """Whether a frame has begun and not ended."""
        return self.state in (self.INSIDE, self.ESCAPED, self.SKIPPING)

    def feed(self, data):
        events = []
        for c in data:
            e = self._step(c)
            if e:
                events.append(e)
        return events

    def _step(self, c):
        if c == STX:
            inside = self.state in (self.INSIDE, self.ESCAPED)
            self.state, self.buf = self.INSIDE, bytearray()
            return ("error", "interrupted") if inside else None
        if self.state == self.OUTSIDE:
            if c in BLANK:
                return None
            self.state = self.JUNK
            return ("error", "stray")
        if self.state == self.JUNK:
            return None
        if self.state == self.SKIPPING:
            if c == ETX:
                self.state = self.OUTSIDE
            return None
        if self.state == self.ESCAPED:
            b = c ^ 0x40
            if b not in SPECIAL:
                self.state = self.OUTSIDE if c == ETX else self.SKIPPING
                return ("error", "escape")
            self.state = self.INSIDE
        else:
            if c == ETX:
                self.state = self.OUTSIDE
                return ("frame", bytes(self.buf))
            if c == DLE:
                self.state = self.ESCAPED
                return None
            b = c
        if len(self.buf) == self.limit:
            self.state = self.SKIPPING
            return ("error", "too-long")
        self.buf.append(b)
        return None
