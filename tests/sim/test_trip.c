/* trip over TCP against a real sim/b14 process: each error path of
 * docs/trip-protocol.md, device exclusion between two clients, and a client
 * killed while it holds a device.
 *
 *   test_trip B14 PORT-BASE TMPDIR
 *
 * Nothing here depends on timing except bounded waits for the server. */
#include <errno.h>
#include <math.h>
#include <netinet/in.h>
#include <arpa/inet.h>
#include <poll.h>
#include <signal.h>
#include <stdlib.h>
#include <string.h>
#include <sys/prctl.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>
#include "check.h"
#include "../../sim/frame.h"
#include "../../sim/trip.h"

static int port_base;
static pid_t server;

typedef struct {
    int fd;
    frame_parser p;
    unsigned char buf[4096];
} conn;

static int dial(conn *c, int robot)
{
    struct sockaddr_in sa = { .sin_family = AF_INET,
                              .sin_port = htons(port_base + 100 + robot) };
    inet_pton(AF_INET, "127.0.0.1", &sa.sin_addr);
    c->fd = socket(AF_INET, SOCK_STREAM, 0);
    frame_init(&c->p, c->buf, sizeof c->buf - 1);
    return connect(c->fd, (struct sockaddr *)&sa, sizeof sa);
}

static void send_raw(conn *c, const void *data, size_t n)
{
    if (write(c->fd, data, n) != (ssize_t)n)
        perror("test_trip: write");
}

static void send_frame(conn *c, const char *payload, size_t n)
{
    unsigned char out[8192];
    send_raw(c, out, frame_encode((const unsigned char *)payload, n, out));
}

/* The next frame's payload as a string; "" on a closed connection or after
 * 10 s of silence. */
static const char *next_reply(conn *c)
{
    for (;;) {
        unsigned char b;
        enum frame_event ev;
        struct pollfd pfd = { c->fd, POLLIN, 0 };
        if (poll(&pfd, 1, 10000) <= 0 || read(c->fd, &b, 1) != 1)
            return "";
        frame_feed(&c->p, &b, 1, &ev);
        if (ev == FRAME_OK) {
            c->buf[c->p.len] = 0;
            return (const char *)c->buf;
        }
    }
}

static const char *ask(conn *c, const char *payload)
{
    send_frame(c, payload, strlen(payload));
    return next_reply(c);
}

static int starts(const char *s, const char *prefix)
{
    return strncmp(s, prefix, strlen(prefix)) == 0;
}

static int closed(conn *c)
{
    char b;
    struct pollfd pfd = { c->fd, POLLIN, 0 };
    while (poll(&pfd, 1, 10000) > 0) {
        ssize_t n = read(c->fd, &b, 1);
        if (n <= 0)
            return 1;
    }
    return 0;
}

static void test_basics(void)
{
    conn c;
    CHECK("connect", dial(&c, 0) == 0);
    CHECK("ping", strcmp(ask(&c, "1 ping"), "1 ok pong") == 0);
    CHECK("who names the robot", strcmp(ask(&c, "2 who"), "2 ok moseley b14-sim") == 0);
    CHECK("open base", strcmp(ask(&c, "3 open base"), "3 ok") == 0);
    CHECK("reckon", strcmp(ask(&c, "4 base reckon"), "4 ok 0.0 0.0 0.00") == 0);
    CHECK("open sonar", strcmp(ask(&c, "5 open sonar"), "5 ok") == 0);
    {
        const char *r = ask(&c, "6 sonar read");
        int spaces = 0;
        for (; *r; r++)
            spaces += *r == ' ';
        CHECK("sonar read gives 16 ranges",
              starts((char *)c.buf, "6 ok ") && spaces == 17);
    }
    CHECK("open speech", strcmp(ask(&c, "7 open speech"), "7 ok") == 0);
    {
        const char say[] = "8 speech say stx\002 etx\003 dle\020 end";
        send_frame(&c, say, sizeof say - 1);
        CHECK("every special byte survives stuffing in a request",
              strcmp(next_reply(&c), "8 ok") == 0);
    }
    CHECK("buttons press needs no open",
          strcmp(ask(&c, "9 buttons press 2"), "9 ok") == 0);
    ask(&c, "10 open buttons");
    CHECK("buttons read shows the press",
          strcmp(ask(&c, "11 buttons read"), "11 ok 0 0 1 0") == 0);
    CHECK("and clears it", strcmp(ask(&c, "12 buttons read"), "12 ok 0 0 0 0") == 0);
    ask(&c, "13 open lights");
    CHECK("lights set", strcmp(ask(&c, "14 lights set 1 0 1 1"), "14 ok") == 0);
    CHECK("lights read", strcmp(ask(&c, "15 lights read"), "15 ok 1 0 1 1") == 0);
    ask(&c, "16 open battery");
    CHECK("battery read", starts(ask(&c, "17 battery read"), "17 ok 13."));
    close(c.fd);
}

/* Poll base status (the base open on c) until the motion is over, at most
 * 10 s; the heading it ends at. */
static double await_still(conn *c)
{
    double x, y, h = 999, rv;
    int tv, moving = 1, stalled, k;
    for (k = 0; k < 500 && moving; k++) {
        if (sscanf(ask(c, "99 base status"), "99 ok %lf %lf %lf %d %lf %d %d",
                   &x, &y, &h, &tv, &rv, &moving, &stalled) != 7)
            break;
        if (moving)
            usleep(20000);
    }
    return h;
}

/* moseley, at the origin facing +x, has the lab's one box 1500 mm ahead. */
static void test_fiducial(void)
{
    conn c;
    int n = -1, id = -1;
    double range = 0, bearing = 99, orientation = 99;
    dial(&c, 0);
    CHECK("fiducial read needs the device open",
          starts(ask(&c, "1 fiducial read"), "1 err not-open open fiducial first"));
    CHECK("open fiducial", strcmp(ask(&c, "2 open fiducial"), "2 ok") == 0);
    CHECK("fiducial read takes no arguments",
          starts(ask(&c, "3 fiducial read 1"), "3 err args"));
    sscanf(ask(&c, "4 fiducial read"), "4 ok %d %d %lf %lf %lf",
           &n, &id, &range, &bearing, &orientation);
    CHECK("fiducial read: the box ahead, its range, bearing and orientation",
          n == 1 && id == 0 && range == 1500 && bearing == 0 && orientation == 0);
    CHECK("no angle is answered as -0.0", strstr((char *)c.buf, "-0.0") == NULL);
    ask(&c, "5 open base");
    ask(&c, "6 base rotate 180");
    CHECK("fiducial test: the robot turns round", fabs(fabs(await_still(&c)) - 180) < 1);
    CHECK("turned away it sees nothing",
          strcmp(ask(&c, "8 fiducial read"), "8 ok 0") == 0);
    ask(&c, "9 base rotate -180");
    CHECK("fiducial test: and back", fabs(await_still(&c)) < 1);
    close(c.fd);
}

static void test_errors(void)
{
    conn c;
    char big[3000];
    dial(&c, 0);
    CHECK("unknown command",
          strcmp(ask(&c, "1 dance"), "1 err unknown no command or device dance") == 0);
    CHECK("unknown command of a device",
          strcmp(ask(&c, "2 base fly"), "2 err unknown base has no command fly") == 0);
    ask(&c, "3 open base");
    CHECK("unknown base command",
          starts(ask(&c, "4 base fly"), "4 err unknown base has no command fly"));
    CHECK("too few arguments", starts(ask(&c, "5 base goto 1"), "5 err args"));
    CHECK("too many arguments", starts(ask(&c, "6 base stop now"), "6 err args"));
    CHECK("not a number",
          starts(ask(&c, "7 base rotate left"), "7 err args left is not a number"));
    CHECK("not finite", starts(ask(&c, "8 base rotate inf"), "8 err args"));
    CHECK("device not open",
          starts(ask(&c, "9 ir read"), "9 err not-open open ir first"));
    CHECK("open of no device", starts(ask(&c, "10 open wings"), "10 err unknown"));
    CHECK("no tag", starts(ask(&c, "ping"), "0 err syntax"));
    CHECK("tag 0 is the server's", starts(ask(&c, "0 ping"), "0 err syntax"));
    CHECK("empty frame", starts(ask(&c, ""), "0 err syntax"));
    CHECK("bad button", starts(ask(&c, "11 buttons press 7"), "11 err args"));
    send_raw(&c, "garbage", 7);
    CHECK("bytes outside a frame",
          starts(ask(&c, "12 ping"), "0 err framing byte outside"));
    CHECK("and the next frame is fine", strcmp(next_reply(&c), "12 ok pong") == 0);
    send_raw(&c, "\0021 pi\0022 ping\003", 13);
    CHECK("STX inside a frame",
          starts(next_reply(&c), "0 err framing frame interrupted"));
    CHECK("the frame after it is answered", strcmp(next_reply(&c), "2 ok pong") == 0);
    send_raw(&c, "\0023 \020Zping\003", 10);
    CHECK("bad escape", starts(next_reply(&c), "0 err framing bad escape"));
    memset(big, 'x', sizeof big);
    memcpy(big, "13 speech say ", 14);
    send_frame(&c, big, sizeof big);
    CHECK("oversize frame", starts(next_reply(&c), "0 err too-long"));
    CHECK("connection still serves", strcmp(ask(&c, "14 ping"), "14 ok pong") == 0);
    {
        const char two[] = "\00215 ping\003\00216 who\003";
        size_t i;
        for (i = 0; i < sizeof two - 1; i++)
            send_raw(&c, &two[i], 1);
        CHECK("frames sent a byte at a time", strcmp(next_reply(&c), "15 ok pong") == 0
              && strcmp(next_reply(&c), "16 ok moseley b14-sim") == 0);
    }
    close(c.fd);
}

static void test_too_many_errors(void)
{
    conn c;
    int i;
    dial(&c, 0);
    for (i = 0; i < 20; i++)
        send_raw(&c, "\002\020Z\003", 4);
    CHECK("a client that keeps breaking framing is closed", closed(&c));
    close(c.fd);
}

static void test_flood(void)
{
    conn c, d;
    static char burst[1 << 16];
    int i, n = 0;
    dial(&c, 0);
    for (i = 0; n + 10 < (int)sizeof burst; i++)
        n += frame_encode((const unsigned char *)"1 ping", 6, (unsigned char *)burst + n);
    /* never read: replies pile up until the server gives up on us */
    for (i = 0; i < 4096; i++) {
        struct pollfd pfd = { c.fd, POLLOUT, 0 };
        if (poll(&pfd, 1, 2000) <= 0 || send(c.fd, burst, n, MSG_NOSIGNAL) < 0)
            break;
    }
    dial(&d, 1);
    CHECK("others are served during a flood",
          strcmp(ask(&d, "1 ping"), "1 ok pong") == 0);
    CHECK("a flooding client that never reads is dropped", i < 4096);
    close(c.fd);
    close(d.fd);
}

static void test_stall(void)
{
    conn c, d;
    dial(&c, 0);
    send_raw(&c, "\0021 pi", 5);
    dial(&d, 0);
    CHECK("others are served while one stalls",
          strcmp(ask(&d, "1 ping"), "1 ok pong") == 0);
    CHECK("a stalled frame gets its error", starts(next_reply(&c), "0 err stalled"));
    CHECK("and the connection is closed", closed(&c));
    close(c.fd);
    close(d.fd);
}

static void test_exclusion(void)
{
    conn a, b;
    dial(&a, 0);
    dial(&b, 0);
    CHECK("first client opens base", strcmp(ask(&a, "1 open base"), "1 ok") == 0);
    CHECK("second is refused, naming the device",
          strcmp(ask(&b, "1 open base"),
                 "1 err held base is held by another client") == 0);
    CHECK("second may open another device", strcmp(ask(&b, "2 open sonar"), "2 ok") == 0);
    CHECK("first may not have sonar now",
          starts(ask(&a, "2 open sonar"), "2 err held sonar"));
    CHECK("close releases", strcmp(ask(&a, "3 close base"), "3 ok") == 0);
    CHECK("then the second gets it", strcmp(ask(&b, "3 open base"), "3 ok") == 0);
    close(a.fd);
    close(b.fd);
    {
        conn e;
        int k, ok = 0;
        dial(&e, 1);
        CHECK("ernst's base is a different lock",
              strcmp(ask(&e, "1 open base"), "1 ok") == 0);
        close(e.fd);
        /* b's locks go when its connection does */
        dial(&e, 0);
        for (k = 0; k < 100 && !ok; k++) {
            ok = strcmp(ask(&e, "2 open base"), "2 ok") == 0;
            if (!ok)
                usleep(50000);
        }
        CHECK("a closed connection loses its locks", ok);
        close(e.fd);
    }
}

/* A client that drives its base and goes away leaves it stopped. */
static void test_dropped_base_stops(void)
{
    conn c, d;
    int moving = 1, k;
    double v = 1;
    char opened[256] = "", status[256] = "";
    dial(&c, 1);
    ask(&c, "1 open base");
    ask(&c, "2 base vel 300 0");
    close(c.fd);
    dial(&d, 1);
    /* The base is free once the server has seen c go; it may still be
     * slowing down then, so its status is read until it stands.  A status
     * read in the server's round that stopped it is idle but still shows
     * the last step's wheel speed, so standing is both, not idle alone.
     * Each wait is up to 10 s. */
    for (k = 0; k < 500; k++) {
        snprintf(opened, sizeof opened, "%s", ask(&d, "1 open base"));
        if (strcmp(opened, "1 ok") == 0)
            break;
        usleep(20000);
    }
    for (k = 0; k < 500 && (moving || v != 0); k++) {
        snprintf(status, sizeof status, "%s", ask(&d, "2 base status"));
        if (sscanf(status, "2 ok %*f %*f %*f %lf %*f %d", &v, &moving) != 2)
            moving = 1;
        if (moving || v != 0)
            usleep(20000);
    }
    if (moving || v != 0)
        fprintf(stderr, "test_trip: last open reply \"%s\", last status \"%s\"\n",
                opened, status);
    CHECK("a base whose client went away stops", !moving && v == 0);
    ask(&d, "3 close base");
    close(d.fd);
}

static void test_killed_client(void)
{
    int ready[2], k, held = 0, ok = 0;
    char x;
    pid_t child;
    conn c;
    if (pipe(ready) < 0)
        return;
    child = fork();
    if (child == 0) {
        conn h;
        dial(&h, 1);
        if (strcmp(ask(&h, "1 open base"), "1 ok") == 0 && write(ready[1], "y", 1) == 1)
            pause();
        _exit(1);
    }
    CHECK("holder got the base", read(ready[0], &x, 1) == 1);
    dial(&c, 1);
    held = starts(ask(&c, "1 open base"), "1 err held base");
    CHECK("held while the holder lives", held);
    kill(child, SIGKILL);
    waitpid(child, NULL, 0);
    for (k = 0; k < 100 && !ok; k++) {
        ok = strcmp(ask(&c, "2 open base"), "2 ok") == 0;
        if (!ok)
            usleep(50000);
    }
    CHECK("a killed client's device is free", ok);
    close(c.fd);
    close(ready[0]);
    close(ready[1]);
}

static void test_stream(void)
{
    conn c;
    int k, events = 0;
    dial(&c, 1);
    ask(&c, "1 open sonar");
    ask(&c, "2 sonar start");
    CHECK("sonar stream on", strcmp(ask(&c, "3 sonar stream on"), "3 ok") == 0);
    for (k = 0; k < 3; k++)
        events += starts(next_reply(&c), "0 sonar ");
    CHECK("started sonars stream their readings with tag 0", events == 3);
    send_frame(&c, "4 sonar stream off", 18);
    for (k = 0; k < 20 && !starts(next_reply(&c), "4 ok"); k++)
        ;
    CHECK("and stop when told", k < 20);
    close(c.fd);
}

static void test_motion(void)
{
    conn c;
    int k, moving = 1;
    double x = 0, y = 0, h = 0;
    dial(&c, 0);
    ask(&c, "1 open base");
    CHECK("goto accepted", strcmp(ask(&c, "2 base goto 500 -300"), "2 ok") == 0);
    for (k = 0; k < 600 && moving; k++) {
        int tv, st;
        double rv;
        usleep(20000);
        sscanf(ask(&c, "3 base status"), "3 ok %lf %lf %lf %d %lf %d %d",
               &x, &y, &h, &tv, &rv, &moving, &st);
    }
    CHECK("goto over trip arrives within 2 cm",
          (x - 500) * (x - 500) + (y + 300) * (y + 300) < 400);
    close(c.fd);
}

/* Frames sent in one write reach the server in one read, and it answers
 * every request of a read before its next step: so the order of the
 * replies below depends on no timing. */
static void send_frames(conn *c, const char *const *payloads, int n)
{
    unsigned char out[8192];
    size_t len = 0;
    int i;
    for (i = 0; i < n; i++)
        len += frame_encode((const unsigned char *)payloads[i], strlen(payloads[i]),
                            out + len);
    send_raw(c, out, len);
}

/* base await: answered at once when idle, else once the motion is over,
 * with other requests answered meanwhile. */
static void test_await(void)
{
    static const char *const turn[] = {
        "3 base rotate 90", "4 base await", "5 base reckon" };
    static const char *const spin[] = {
        "7 base rotate 3600", "8 base await", "9 base stop" };
    conn c;
    char reply[256];
    double x, y, h, h0 = 0;
    char crowd[MAX_AWAITS + 3][32];
    const char *crowds[MAX_AWAITS + 3];
    int stalled = -1, moving = -1, k, answered = 0;
    dial(&c, 0);
    ask(&c, "1 open base");
    CHECK("await on an idle base answers at once",
          sscanf(ask(&c, "2 base await"), "2 ok %lf %lf %lf %d",
                 &x, &y, &h0, &stalled) == 4 && stalled == 0);
    send_frames(&c, turn, 3);
    CHECK("a motion is accepted", strcmp(next_reply(&c), "3 ok") == 0);
    CHECK("a request after an await is answered before the motion ends",
          starts(next_reply(&c), "5 ok "));
    snprintf(reply, sizeof reply, "%s", next_reply(&c));
    CHECK("the await is answered once it has",
          sscanf(reply, "4 ok %lf %lf %lf %d", &x, &y, &h, &stalled) == 4
          && stalled == 0 && fabs(remainder(h - h0 - 90, 360)) < 1);
    CHECK("and the base is idle then",
          sscanf(ask(&c, "6 base status"), "6 ok %*f %*f %*f %*f %*f %d", &moving) == 1
          && moving == 0);
    send_frames(&c, spin, 3);
    CHECK("a stop ends the motion an await waits for", strcmp(next_reply(&c), "7 ok") == 0
          && strcmp(next_reply(&c), "9 ok") == 0 && starts(next_reply(&c), "8 ok "));
    for (k = 0; k < MAX_AWAITS + 3; k++)
        snprintf(crowd[k], sizeof crowd[k], "%d base await", 10 + k);
    snprintf(crowd[0], sizeof crowd[0], "10 base rotate 3600");
    snprintf(crowd[MAX_AWAITS + 2], sizeof crowd[0], "%d base stop", 12 + MAX_AWAITS);
    for (k = 0; k < MAX_AWAITS + 3; k++)
        crowds[k] = crowd[k];
    send_frames(&c, crowds, MAX_AWAITS + 3);
    snprintf(reply, sizeof reply, "%d err busy ", 11 + MAX_AWAITS);
    CHECK("awaits beyond MAX_AWAITS are refused",
          strcmp(next_reply(&c), "10 ok") == 0 && starts(next_reply(&c), reply));
    next_reply(&c);
    for (k = 0; k < MAX_AWAITS; k++) {
        snprintf(reply, sizeof reply, "%d ok ", 11 + k);
        answered += starts(next_reply(&c), reply);
    }
    CHECK("and the others all answered when the motion ends", answered == MAX_AWAITS);
    close(c.fd);
}

/* The heading field of a reckon reply. */
static const char *heading_of(const char *reply)
{
    static char h[32];
    char tag[16];
    double x, y;
    if (sscanf(reply, "%15s ok %lf %lf %31s", tag, &x, &y, h) != 4)
        return "";
    return h;
}

/* Headings are answered in (-180, 180] as printed: one just above -180
 * that rounds to -180 at two decimals is 180. */
static void test_heading_range(void)
{
    conn c;
    int k, ok = 0;
    dial(&c, 0);
    for (k = 0; k < 100 && !ok; k++) {     /* test_motion's client may still hold it */
        ok = strcmp(ask(&c, "1 open base"), "1 ok") == 0;
        if (!ok)
            usleep(50000);
    }
    CHECK("open base for the heading range", ok);
    ask(&c, "2 base set-heading -179.999");
    CHECK("a heading that rounds to -180 is answered as 180",
          strcmp(heading_of(ask(&c, "3 base reckon")), "180.00") == 0);
    ask(&c, "4 base set-heading -180");
    CHECK("set-heading -180 is answered as 180",
          strcmp(heading_of(ask(&c, "5 base reckon")), "180.00") == 0);
    ask(&c, "6 base set-heading 180");
    CHECK("set-heading 180 is answered as 180",
          strcmp(heading_of(ask(&c, "7 base reckon")), "180.00") == 0);
    ask(&c, "8 base set-heading -179.99");
    CHECK("a heading that rounds above -180 stays negative",
          strcmp(heading_of(ask(&c, "9 base reckon")), "-179.99") == 0);
    ask(&c, "10 base set-heading -179.999");
    {
        char h[32] = "";
        double x, y, rv;
        int tv, moving, stalled;
        sscanf(ask(&c, "11 base status"), "11 ok %lf %lf %31s %d %lf %d %d",
               &x, &y, h, &tv, &rv, &moving, &stalled);
        CHECK("status answers the heading in range too", strcmp(h, "180.00") == 0);
    }
    close(c.fd);
}

int main(int argc, char **argv)
{
    int ready[2], status;
    char line[256];
    FILE *out;
    if (argc != 4) {
        fprintf(stderr, "usage: test_trip B14 PORT-BASE TMPDIR\n");
        return 2;
    }
    port_base = atoi(argv[2]);
    signal(SIGPIPE, SIG_IGN);
    {
        char lab[512], trace[512], locks[512];
        snprintf(lab, sizeof lab, "%s/lab.scm", argv[3]);
        snprintf(trace, sizeof trace, "%s/run.svg", argv[3]);
        snprintf(locks, sizeof locks, "%s/locks", argv[3]);
        out = fopen(lab, "w");
        fputs("(lab t (aspace moseley (robot (pose 0 0 0)))\n"
              "       (aspace ernst (robot (pose -1000 1000 90) (tethered #t)))\n"
              "       (world (wall -3000 -3000 3000 -3000) (wall 3000 -3000 3000 3000)\n"
              "              (wall 3000 3000 -3000 3000) (wall -3000 3000 -3000 -3000)\n"
              "              (box 1500 0 600 600 0))\n"
              "       (simulator (speed 4) (stall-timeout 1)))\n", out);
        fclose(out);
        if (pipe(ready) < 0)
            return 2;
        server = fork();
        if (server == 0) {
            char pb[16];
            snprintf(pb, sizeof pb, "%d", port_base);
            dup2(ready[1], 1);
            prctl(PR_SET_PDEATHSIG, SIGTERM);   /* no stray server if we crash */
            execl(argv[1], argv[1], lab, "--port-base", pb, "--trace", trace,
                  "--lock-dir", locks, (char *)NULL);
            _exit(127);
        }
        close(ready[1]);
        out = fdopen(ready[0], "r");
        while (fgets(line, sizeof line, out) && strcmp(line, "b14: ready\n") != 0)
            ;
        test_basics();
        test_fiducial();
        test_errors();
        test_too_many_errors();
        test_flood();
        test_stall();
        test_exclusion();
        test_killed_client();
        test_dropped_base_stops();
        test_stream();
        test_motion();
        test_await();
        test_heading_range();
        kill(server, SIGTERM);
        waitpid(server, &status, 0);
        CHECK("SIGTERM ends the server with status 0",
              WIFEXITED(status) && WEXITSTATUS(status) == 0);
        {
            struct stat st;
            char tmp[520];
            snprintf(tmp, sizeof tmp, "%s.tmp", trace);
            CHECK("the trace is written whole",
                  stat(trace, &st) == 0 && st.st_size > 1000 && stat(tmp, &st) < 0);
        }
        fclose(out);
    }
    return check_summary();
}
