/* The frame parser on its own: stuffing of every special byte, partial reads,
 * and each error path of docs/trip-protocol.md. */
#include <string.h>
#include "check.h"
#include "../../sim/frame.h"

/* Feed everything, collecting events (and the payload of the last frame). */
static int run(frame_parser *p, const unsigned char *in, size_t n,
               enum frame_event *evs, int max)
{
    int k = 0;
    while (n > 0) {
        enum frame_event e;
        size_t used = frame_feed(p, in, n, &e);
        in += used;
        n -= used;
        if (e != FRAME_NONE && k < max)
            evs[k++] = e;
    }
    return k;
}

static int run_str(frame_parser *p, const char *s, enum frame_event *evs)
{
    return run(p, (const unsigned char *)s, strlen(s), evs, 8);
}

static void test_round_trip_every_byte(void)
{
    unsigned char payload[256], enc[2 * 256 + 2], buf[512];
    frame_parser p;
    enum frame_event evs[4];
    size_t n;
    int i, k, specials = 0;

    for (i = 0; i < 256; i++)
        payload[i] = (unsigned char)i;
    n = frame_encode(payload, 256, enc);
    for (i = 1; i < (int)n - 1; i++)
        specials += enc[i] == STX || enc[i] == ETX;
    CHECK("no bare STX/ETX inside an encoded frame", specials == 0);
    CHECK("three bytes stuffed", n == 256 + 3 + 2);
    frame_init(&p, buf, sizeof buf);
    k = run(&p, enc, n, evs, 4);
    CHECK("every byte round-trips", k == 1 && evs[0] == FRAME_OK && p.len == 256
          && memcmp(buf, payload, 256) == 0);
}

static void test_each_special_byte(void)
{
    const unsigned char special[3] = { STX, ETX, DLE };
    const unsigned char want[3][5] = {
        { STX, DLE, 'B', ETX }, { STX, DLE, 'C', ETX }, { STX, DLE, 'P', ETX } };
    int i;
    for (i = 0; i < 3; i++) {
        unsigned char enc[8];
        size_t n = frame_encode(&special[i], 1, enc);
        CHECK("special byte stuffed as DLE x^0x40",
              n == 4 && memcmp(enc, want[i], 4) == 0);
    }
}

static void test_byte_at_a_time(void)
{
    const unsigned char in[] = "\002 7 ping\003\002 8 who\003";
    unsigned char buf[64];
    frame_parser p;
    size_t i;
    int frames = 0, pending_mid = 0;
    frame_init(&p, buf, sizeof buf);
    for (i = 0; i < sizeof in - 1; i++) {
        enum frame_event e;
        frame_feed(&p, &in[i], 1, &e);
        if (e == FRAME_OK)
            frames++;
        if (i == 3)
            pending_mid = frame_pending(&p);
    }
    CHECK("frames survive one-byte reads", frames == 2);
    CHECK("partial frame is pending", pending_mid);
    CHECK("last payload", p.len == 6 && memcmp(buf, " 8 who", 6) == 0);
}

static void test_many_frames_one_read(void)
{
    const unsigned char in[] = "\r\n\0021 a\003 \0022 b\003\n\0023 c\003";
    unsigned char buf[64];
    frame_parser p;
    enum frame_event evs[8];
    int k;
    frame_init(&p, buf, sizeof buf);
    k = run(&p, in, sizeof in - 1, evs, 8);
    CHECK("three frames, blanks between ignored",
          k == 3 && evs[0] == FRAME_OK && evs[1] == FRAME_OK && evs[2] == FRAME_OK);
}

static void test_errors(void)
{
    unsigned char buf[8];
    frame_parser p;
    enum frame_event evs[8];
    int k;

    frame_init(&p, buf, sizeof buf);
    k = run_str(&p, "junk\003more\0021 ok\003", evs);
    CHECK("stray bytes reported once, next frame fine",
          k == 2 && evs[0] == FRAME_ERR_STRAY && evs[1] == FRAME_OK && p.len == 4);

    frame_init(&p, buf, sizeof buf);
    k = run_str(&p, "\0021 ha\0022 ok\003", evs);
    CHECK("STX inside a frame restarts it",
          k == 2 && evs[0] == FRAME_ERR_INTERRUPTED && evs[1] == FRAME_OK
          && p.len == 4 && memcmp(buf, "2 ok", 4) == 0);

    frame_init(&p, buf, sizeof buf);
    k = run_str(&p, "\0021 \020Zxx\003\0022 ok\003", evs);
    CHECK("bad escape skips to ETX",
          k == 2 && evs[0] == FRAME_ERR_ESCAPE && p.bad == 'Z' && evs[1] == FRAME_OK);

    frame_init(&p, buf, sizeof buf);
    k = run_str(&p, "\0021\020\003\0022 ok\003", evs);
    CHECK("DLE before ETX is a bad escape that ends the frame",
          k == 2 && evs[0] == FRAME_ERR_ESCAPE && evs[1] == FRAME_OK);

    frame_init(&p, buf, sizeof buf);
    k = run_str(&p, "\002123456789\003\0022 ok\003", evs);
    CHECK("oversize frame rejected, next one fine",
          k == 2 && evs[0] == FRAME_ERR_TOO_LONG && evs[1] == FRAME_OK);

    frame_init(&p, buf, sizeof buf);
    k = run_str(&p, "\00212345678\003", evs);
    CHECK("frame of exactly the limit accepted",
          k == 1 && evs[0] == FRAME_OK && p.len == 8);

    frame_init(&p, buf, sizeof buf);
    k = run_str(&p, "\002\003", evs);
    CHECK("empty frame is a frame", k == 1 && evs[0] == FRAME_OK && p.len == 0);
}

int main(void)
{
    test_round_trip_every_byte();
    test_each_special_byte();
    test_byte_at_a_time();
    test_many_frames_one_read();
    test_errors();
    return check_summary();
}
