/* libFuzzer target: bytes as they might arrive on a trip socket, cut into
 * reads at places the input chooses, through the frame parser and on into
 * the request handler of a one-robot world.  Checks that parsing never
 * overruns, that every payload re-encodes to a frame that parses back to
 * itself, and that every reply fits and carries a tag, a base await's
 * deferred reply too. */
#include <dirent.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>
#include "../../sim/frame.h"
#include "../../sim/trip.h"

static world *w;
static lab l;
static char lockdir[] = "/tmp/b14-fuzz-XXXXXX";

/* The lock files the fuzzed opens made, and their folder, go at exit. */
static void remove_lockdir(void)
{
    DIR *d = opendir(lockdir);
    struct dirent *e;
    char path[sizeof lockdir + 300];
    while (d && (e = readdir(d)))
        if (e->d_name[0] != '.') {
            snprintf(path, sizeof path, "%s/%s", lockdir, e->d_name);
            unlink(path);
        }
    if (d)
        closedir(d);
    rmdir(lockdir);
}

static void setup(void)
{
    lab_robot r;
    lab_defaults(&l);
    l.b14.max_frame = 256;
    lab_add_wall(&l, 2000, -2000, 2000, 2000, 50);
    memset(&r, 0, sizeof r);
    strcpy(r.name, "fuzzy");
    r.battery = 13;
    lab_add_robot(&l, &r);
    w = world_new(&l);
    if (!mkdtemp(lockdir))
        abort();
    atexit(remove_lockdir);
}

static void round_trip(const unsigned char *p, size_t n)
{
    unsigned char enc[2 * 256 + 2], buf[256];
    frame_parser q;
    enum frame_event ev;
    frame_init(&q, buf, sizeof buf);
    frame_feed(&q, enc, frame_encode(p, n, enc), &ev);
    if (ev != FRAME_OK || q.len != n || memcmp(buf, p, n) != 0)
        abort();
}

static void check_reply(const char *reply, size_t len, size_t cap)
{
    if (len == 0 || len >= cap || reply[0] < '0' || reply[0] > '9')
        abort();
}

/* The base awaits whose replies the session holds back. */
static int awaits(const trip_session *s)
{
    int i, n = 0;
    for (i = 0; i < MAX_AWAITS; i++)
        n += s->awaits[i] != 0;
    return n;
}

/* Only a base await held back goes without a reply now. */
static void answer(trip_session *s, const unsigned char *p, size_t n)
{
    char reply[1024];
    int held = awaits(s);
    size_t len = trip_handle(s, (const char *)p, n, reply, sizeof reply);
    if (len > 0 || awaits(s) != held + 1)
        check_reply(reply, len, sizeof reply);
}

/* Once the base stops, every await held back is answered. */
static void answer_awaits(trip_session *s)
{
    char reply[1024];
    size_t len;
    robot_stop(w, 0);
    while ((len = trip_event(s, reply, sizeof reply)) > 0)
        check_reply(reply, len, sizeof reply);
    if (awaits(s) != 0)
        abort();
}

int LLVMFuzzerTestOneInput(const unsigned char *data, size_t size)
{
    unsigned char buf[256];
    frame_parser p;
    trip_session s;
    size_t cut;
    if (!w)
        setup();
    frame_init(&p, buf, sizeof buf);
    trip_begin(&s, w, 0, lockdir);
    /* the first byte chooses how the rest is split into reads */
    cut = size ? data[0] % 17 + 1 : 1;
    if (size)
        data++, size--;
    while (size > 0) {
        size_t chunk = size < cut ? size : cut;
        while (chunk > 0) {
            enum frame_event ev;
            size_t used = frame_feed(&p, data, chunk, &ev);
            if (used == 0 || used > chunk || p.len > p.cap)
                abort();
            if (ev == FRAME_OK) {
                round_trip(p.buf, p.len);
                answer(&s, p.buf, p.len);
            }
            data += used;
            size -= used;
            chunk -= used;
        }
    }
    answer_awaits(&s);
    trip_end(&s);
    return 0;
}
