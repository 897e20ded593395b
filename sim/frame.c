#include "frame.h"

enum { OUTSIDE, JUNK, INSIDE, ESCAPED, SKIPPING };

void frame_init(frame_parser *p, unsigned char *buf, size_t cap)
{
    p->buf = buf;
    p->cap = cap;
    p->len = 0;
    p->state = OUTSIDE;
    p->bad = 0;
}

int frame_pending(const frame_parser *p)
{
    return p->state == INSIDE || p->state == ESCAPED || p->state == SKIPPING;
}

static int is_blank(unsigned char c)
{
    return c == '\r' || c == '\n' || c == ' ' || c == '\t';
}

static int unstuff(unsigned char c, unsigned char *out)
{
    unsigned char b = c ^ 0x40;
    if (b != STX && b != ETX && b != DLE)
        return 0;
    *out = b;
    return 1;
}

/* One byte through the machine; returns the event it completes. */
static enum frame_event step(frame_parser *p, unsigned char c)
{
    unsigned char b;

    if (c == STX) {
        int was_inside = p->state == INSIDE || p->state == ESCAPED;
        p->state = INSIDE;
        p->len = 0;
        return was_inside ? FRAME_ERR_INTERRUPTED : FRAME_NONE;
    }
    switch (p->state) {
    case OUTSIDE:
        if (is_blank(c))
            return FRAME_NONE;
        p->state = JUNK;
        p->bad = c;
        return FRAME_ERR_STRAY;
    case JUNK:
        return FRAME_NONE;
    case SKIPPING:
        if (c == ETX)
            p->state = OUTSIDE;
        return FRAME_NONE;
    case ESCAPED:
        if (!unstuff(c, &b)) {
            p->state = c == ETX ? OUTSIDE : SKIPPING;
            p->bad = c;
            return FRAME_ERR_ESCAPE;
        }
        p->state = INSIDE;
        break;
    default: /* INSIDE */
        if (c == ETX) {
            p->state = OUTSIDE;
            return FRAME_OK;
        }
        if (c == DLE) {
            p->state = ESCAPED;
            return FRAME_NONE;
        }
        b = c;
    }
    if (p->len == p->cap) {
        p->state = SKIPPING;
        return FRAME_ERR_TOO_LONG;
    }
    p->buf[p->len++] = b;
    return FRAME_NONE;
}

size_t frame_feed(frame_parser *p, const unsigned char *data, size_t n,
                  enum frame_event *ev)
{
    size_t i;
    for (i = 0; i < n; i++) {
        enum frame_event e = step(p, data[i]);
        if (e != FRAME_NONE) {
            *ev = e;
            return i + 1;
        }
    }
    *ev = FRAME_NONE;
    return n;
}

size_t frame_encode(const unsigned char *payload, size_t n, unsigned char *out)
{
    size_t i, k = 0;
    out[k++] = STX;
    for (i = 0; i < n; i++) {
        unsigned char c = payload[i];
        if (c == STX || c == ETX || c == DLE) {
            out[k++] = DLE;
            c ^= 0x40;
        }
        out[k++] = c;
    }
    out[k++] = ETX;
    return k;
}

const char *frame_error_text(enum frame_event ev)
{
    switch (ev) {
    case FRAME_ERR_STRAY: return "framing byte outside a frame";
    case FRAME_ERR_INTERRUPTED: return "framing frame interrupted by STX";
    case FRAME_ERR_ESCAPE: return "framing bad escape after DLE";
    case FRAME_ERR_TOO_LONG: return "too-long frame over the size limit";
    default: return "";
    }
}
