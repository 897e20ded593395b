/* trip framing: STX payload ETX, with STX, ETX and DLE stuffed as DLE, byte^0x40.
 * See docs/trip-protocol.md.  The parser is a byte-at-a-time state machine so
 * that partial reads, many frames per read and hostile input all take the
 * same path. */
#ifndef FRAME_H
#define FRAME_H
#include <stddef.h>

enum { STX = 0x02, ETX = 0x03, DLE = 0x10 };

enum frame_event {
    FRAME_NONE,          /* input used up, nothing to report */
    FRAME_OK,            /* a whole payload is in buf[0..len) */
    FRAME_ERR_STRAY,     /* junk between frames (reported once per run) */
    FRAME_ERR_INTERRUPTED, /* STX inside a frame */
    FRAME_ERR_ESCAPE,    /* DLE followed by a byte that is not B, C or P */
    FRAME_ERR_TOO_LONG   /* payload over the limit */
};

typedef struct {
    unsigned char *buf;  /* caller's storage, cap bytes */
    size_t cap, len;
    int state;
    unsigned char bad;   /* the offending byte of the last error */
} frame_parser;

void frame_init(frame_parser *p, unsigned char *buf, size_t cap);
/* Consume bytes of data[0..n) up to and including the first that completes an
 * event; return how many were consumed and store the event. */
size_t frame_feed(frame_parser *p, const unsigned char *data, size_t n,
                  enum frame_event *ev);
/* True while part of a frame has been read. */
int frame_pending(const frame_parser *p);
/* Encode payload into out (at least 2n+2 bytes); return the frame's length. */
size_t frame_encode(const unsigned char *payload, size_t n, unsigned char *out);
const char *frame_error_text(enum frame_event ev);
#endif
