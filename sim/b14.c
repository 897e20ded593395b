/* b14: the simulated B14s of a lab, each serving trip on its own port.
 *
 *   b14 LAB-FILE [--port-base N] [--interface ADDR] [--speed X | --fast]
 *                [--seed N] [--trace FILE.svg] [--lock-dir DIR]
 *
 * One process, one thread of control: poll() for the clients of every
 * robot, answer whole frames as they arrive, and step the world whenever the
 * clock says a step is due (a fixed step, scaled by --speed, or back to back
 * with --fast).  Prints "b14: NAME trip HOST:PORT" per robot, then
 * "b14: ready".  SIGTERM or SIGINT ends the run: the trace is written and
 * the process exits 0. */
#define _GNU_SOURCE
#include <arpa/inet.h>
#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <poll.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>
#include "frame.h"
#include "trace.h"
#include "trip.h"
#include "alloc.h"

enum {
    MAX_CLIENTS = 256,
    READ_SLICE = 16384,         /* per client per turn: nobody starves */
    MAX_BACKLOG = 65536,        /* unread replies before a client is dropped */
    MAX_FRAME_ERRORS = 16
};

typedef struct {
    int fd;
    trip_session session;
    frame_parser parser;
    unsigned char *payload;
    unsigned char *out;
    size_t outlen;
    int errors;
    double pending_since;       /* wall time a partial frame began, or 0 */
} client;

typedef struct {
    lab lab;
    world *w;
    const char *lockdir;
    int *listeners;
    client *clients[MAX_CLIENTS];
    struct pollfd *fds;         /* poll's arrays: listeners, then clients */
    int *who;                   /* -1 - robot for a listener, else client */
} server;

static volatile sig_atomic_t stopping;

static void on_signal(int sig)
{
    (void)sig;
    stopping = 1;
}

static double wall_now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return ts.tv_sec + ts.tv_nsec * 1e-9;
}

static void die(const char *what)
{
    fprintf(stderr, "b14: %s\n", what);
    exit(2);
}

static void usage(void)
{
    die("usage: b14 LAB-FILE [--port-base N] [--interface ADDR] [--speed X | --fast] "
        "[--seed N] [--trace FILE.svg] [--lock-dir DIR]");
}

/* ---- clients ---------------------------------------------------------- */

static void drop(server *sv, int k)
{
    client *c = sv->clients[k];
    trip_end(&c->session);
    close(c->fd);
    free(c->payload);
    free(c->out);
    free(c);
    sv->clients[k] = NULL;
}

/* Queue a reply; 0, or -1 when the client is too far behind to keep. */
static int send_payload(client *c, const char *p, size_t n)
{
    if (c->outlen + 2 * n + 2 > MAX_BACKLOG)
        return -1;
    c->outlen += frame_encode((const unsigned char *)p, n, c->out + c->outlen);
    return 0;
}

static int flush_out(client *c)
{
    while (c->outlen > 0) {
        ssize_t n = send(c->fd, c->out, c->outlen, MSG_NOSIGNAL);
        if (n < 0)
            return errno == EAGAIN || errno == EWOULDBLOCK || errno == EINTR ? 0 : -1;
        memmove(c->out, c->out + n, c->outlen - n);
        c->outlen -= n;
    }
    return 0;
}

/* Answer every whole frame in data; -1 when the client must go. */
static int take(client *c, const unsigned char *data, size_t n)
{
    char reply[1024];
    while (n > 0) {
        enum frame_event ev;
        size_t used = frame_feed(&c->parser, data, n, &ev), len = 0;
        data += used;
        n -= used;
        if (ev == FRAME_OK) {
            len = trip_handle(&c->session, (const char *)c->parser.buf, c->parser.len,
                              reply, sizeof reply);
        } else if (ev != FRAME_NONE) {
            len = (size_t)snprintf(reply, sizeof reply, "0 err %s", frame_error_text(ev));
            if (++c->errors > MAX_FRAME_ERRORS)
                return -1;
        }
        if (len > 0 && send_payload(c, reply, len) < 0)
            return -1;
    }
    c->pending_since = frame_pending(&c->parser) ? (c->pending_since ? c->pending_since : wall_now()) : 0;
    return 0;
}

static int serve(client *c)
{
    unsigned char buf[READ_SLICE];
    ssize_t n = recv(c->fd, buf, sizeof buf, 0);
    if (n == 0)
        return -1;
    if (n < 0)
        return errno == EAGAIN || errno == EINTR ? 0 : -1;
    return take(c, buf, n);
}

static void accept_client(server *sv, int robot)
{
    int fd = accept4(sv->listeners[robot], NULL, NULL, SOCK_NONBLOCK | SOCK_CLOEXEC), k, one = 1;
    client *c;
    if (fd < 0)
        return;
    for (k = 0; k < MAX_CLIENTS && sv->clients[k]; k++)
        ;
    if (k == MAX_CLIENTS) {
        close(fd);
        return;
    }
    setsockopt(fd, IPPROTO_TCP, TCP_NODELAY, &one, sizeof one);
    c = xcalloc(1, sizeof *c);
    c->fd = fd;
    c->payload = xmalloc(sv->lab.b14.max_frame);
    c->out = xmalloc(MAX_BACKLOG);
    frame_init(&c->parser, c->payload, sv->lab.b14.max_frame);
    trip_begin(&c->session, sv->w, robot, sv->lockdir);
    sv->clients[k] = c;
}

/* Queue every message due to c apart from replies (trip_event); 0, or -1
 * when the client is too far behind to keep. */
static int send_events(client *c)
{
    char event[512];
    size_t n;
    while ((n = trip_event(&c->session, event, sizeof event)) > 0)
        if (send_payload(c, event, n) < 0)
            return -1;
    return 0;
}

/* Deferred replies, asynchronous readings, stalled clients, and the writes
 * that are due. */
static void after_step(server *sv)
{
    double now = wall_now();
    int k;
    for (k = 0; k < MAX_CLIENTS; k++) {
        client *c = sv->clients[k];
        if (!c)
            continue;
        if (send_events(c) < 0) {
            drop(sv, k);
            continue;
        }
        if (c->pending_since && now - c->pending_since > sv->lab.stall_timeout) {
            send_payload(c, "0 err stalled incomplete frame for too long", 43);
            flush_out(c);
            drop(sv, k);
            continue;
        }
        if (flush_out(c) < 0)
            drop(sv, k);
    }
}

/* ---- the loop --------------------------------------------------------- */

static void poll_once(server *sv, int timeout_ms)
{
    struct pollfd *fds = sv->fds;
    int *who = sv->who, n = 0, k, r = sv->w->nrobots;
    for (k = 0; k < r; k++) {
        fds[n] = (struct pollfd){ sv->listeners[k], POLLIN, 0 };
        who[n++] = -1 - k;
    }
    for (k = 0; k < MAX_CLIENTS; k++)
        if (sv->clients[k]) {
            fds[n] = (struct pollfd){ sv->clients[k]->fd, POLLIN | (sv->clients[k]->outlen ? POLLOUT : 0), 0 };
            who[n++] = k;
        }
    if (poll(fds, n, timeout_ms) <= 0)
        return;
    for (k = 0; k < n; k++) {
        if (!fds[k].revents)
            continue;
        if (who[k] < 0) {
            accept_client(sv, -1 - who[k]);
        } else if (sv->clients[who[k]]) {
            client *c = sv->clients[who[k]];
            if (((fds[k].revents & (POLLIN | POLLHUP | POLLERR)) && serve(c) < 0)
                || flush_out(c) < 0)
                drop(sv, who[k]);
        }
    }
}

static void run(server *sv, double speed)
{
    double dt = sv->w->dt, next = wall_now();
    while (!stopping) {
        double now = wall_now();
        int wait = speed > 0 ? (int)fmax(0, ceil((next - now) * 1000)) : 0;
        poll_once(sv, wait);
        now = wall_now();
        if (speed > 0 && now - next > 0.5)
            next = now;         /* far behind: slip rather than race to catch up */
        if (speed == 0 || now >= next) {
            world_step(sv->w);
            next += dt / (speed > 0 ? speed : 1);
        }
        after_step(sv);
    }
}

/* ---- setting up ------------------------------------------------------- */

static int listen_on(const char *addr, int port)
{
    struct sockaddr_in sa = { .sin_family = AF_INET, .sin_port = htons(port) };
    int fd = socket(AF_INET, SOCK_STREAM | SOCK_NONBLOCK | SOCK_CLOEXEC, 0), one = 1;
    if (inet_pton(AF_INET, addr, &sa.sin_addr) != 1)
        die("--interface must be an IPv4 address");
    setsockopt(fd, SOL_SOCKET, SO_REUSEADDR, &one, sizeof one);
    if (fd < 0 || bind(fd, (struct sockaddr *)&sa, sizeof sa) < 0 || listen(fd, 16) < 0) {
        fprintf(stderr, "b14: cannot listen on %s:%d: %s\n", addr, port, strerror(errno));
        exit(2);
    }
    return fd;
}

static char *default_lockdir(int port_base)
{
    const char *tmp = getenv("TMPDIR");
    size_t n = 4096;
    char *dir = xmalloc(n);
    snprintf(dir, n, "%s/b14-locks-%d", tmp && *tmp ? tmp : "/tmp", port_base);
    return dir;
}

/* A lock folder this run made is this run's to clear away. */
static void remove_locks(const server *sv)
{
    char path[4096];
    int i, d;
    for (i = 0; i < sv->lab.nrobots; i++)
        for (d = 0; d < DEVICES; d++) {
            snprintf(path, sizeof path, "%s/%s.%s.lock", sv->lockdir, sv->lab.robots[i].name,
                     trip_device_name(d));
            unlink(path);
        }
    rmdir(sv->lockdir);
}

typedef struct {
    const char *labfile, *trace, *lockdir, *interface;
    int port_base;
    double speed;
    long seed;
} options;

static void parse_options(int argc, char **argv, options *o)
{
    int i;
    memset(o, 0, sizeof *o);
    o->port_base = -1;
    o->speed = -1;
    o->seed = -1;
    for (i = 1; i < argc; i++) {
        const char *a = argv[i], *v = i + 1 < argc ? argv[i + 1] : NULL;
        if (strcmp(a, "--fast") == 0) {
            o->speed = 0;
            continue;
        }
        if (a[0] != '-') {
            if (o->labfile)
                usage();
            o->labfile = a;
            continue;
        }
        if (!v)
            usage();
        i++;
        if (strcmp(a, "--port-base") == 0)
            o->port_base = atoi(v);
        else if (strcmp(a, "--interface") == 0)
            o->interface = v;
        else if (strcmp(a, "--speed") == 0 && atof(v) > 0)
            o->speed = atof(v);
        else if (strcmp(a, "--seed") == 0)
            o->seed = atol(v);
        else if (strcmp(a, "--trace") == 0)
            o->trace = v;
        else if (strcmp(a, "--lock-dir") == 0)
            o->lockdir = v;
        else
            usage();
    }
    if (!o->labfile)
        usage();
}

int main(int argc, char **argv)
{
    static server sv;
    struct sigaction sa;
    options o;
    char err[256];
    struct trace *trace = NULL;         /* the run as an SVG, when asked for */
    const char *env = getenv("MURDOCH_PORT_BASE");
    int i, made_lockdir;

    parse_options(argc, argv, &o);
    if (lab_load(o.labfile, &sv.lab, err, sizeof err) < 0)
        die(err);
    if (env && *env)
        sv.lab.port_base = atoi(env);
    if (o.port_base >= 0)
        sv.lab.port_base = o.port_base;
    if (o.interface)
        snprintf(sv.lab.interface, sizeof sv.lab.interface, "%s", o.interface);
    if (o.speed >= 0)
        sv.lab.speed = o.speed;
    if (o.seed >= 0)
        sv.lab.seed = (unsigned long)o.seed;
    sv.lockdir = o.lockdir ? o.lockdir : default_lockdir(sv.lab.port_base);
    made_lockdir = mkdir(sv.lockdir, 0700) == 0;
    if (!made_lockdir && errno != EEXIST)
        die("cannot make the lock folder");

    memset(&sa, 0, sizeof sa);
    sa.sa_handler = on_signal;
    sigaction(SIGTERM, &sa, NULL);
    sigaction(SIGINT, &sa, NULL);
    signal(SIGPIPE, SIG_IGN);

    sv.w = world_new(&sv.lab);
    if (o.trace) {
        trace = trace_open(o.trace);
        sv.w->observer = trace_observer(trace);
    }
    sv.listeners = xmalloc((sv.lab.nrobots + 1) * sizeof(int));
    sv.fds = xmalloc((sv.lab.nrobots + MAX_CLIENTS) * sizeof *sv.fds);
    sv.who = xmalloc((sv.lab.nrobots + MAX_CLIENTS) * sizeof *sv.who);
    for (i = 0; i < sv.lab.nrobots; i++) {
        int port = lab_trip_port(&sv.lab, &sv.lab.robots[i]);
        sv.listeners[i] = listen_on(sv.lab.interface, port);
        printf("b14: %s trip %s:%d\n", sv.lab.robots[i].name, sv.lab.interface, port);
    }
    printf("b14: ready\n");
    fflush(stdout);

    run(&sv, sv.lab.speed);
    world_sync(sv.w);           /* the last round's readings, for the trace */
    /* Where the boxes ended, for a demo to judge its task by: the room's
     * truth, which no robot is told. */
    for (i = 0; i < sv.lab.nboxes; i++) {
        pose at = physics_box_pose(sv.w->phys, i);
        printf("b14: box %d ends at %.0f %.0f %.1f after %.1f s\n", i, at.x, at.y,
               wrap180(at.heading), world_time(sv.w));
    }
    fflush(stdout);

    for (i = 0; i < MAX_CLIENTS; i++)
        if (sv.clients[i])
            drop(&sv, i);
    for (i = 0; i < sv.lab.nrobots; i++)
        close(sv.listeners[i]);
    if (made_lockdir)
        remove_locks(&sv);
    if (trace && trace_close(trace, sv.w) < 0)
        return 1;
    return 0;
}
