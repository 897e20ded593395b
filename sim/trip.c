#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/file.h>
#include <unistd.h>
#include "trip.h"
#include "alloc.h"

static const char *const device_names[DEVICES] = {
    "base", "sonar", "ir", "bumpers", "skirt", "buttons", "lights", "speech", "battery",
    "fiducial" };

enum { MAX_WORDS = 8 };

const char *trip_device_name(int d)
{
    return device_names[d];
}

/* One request being answered. */
typedef struct {
    trip_session *s;
    world *w;
    int r;
    const char *word[MAX_WORDS];
    int nwords;
    double arg[MAX_WORDS];      /* numeric arguments after DEVICE COMMAND */
    const char *rest;           /* raw text after DEVICE COMMAND, for speech */
    size_t restlen;
    char *out;
    size_t cap, len;
    int deferred;               /* no reply now: trip_event sends it later */
} request;

static void put(request *q, const char *fmt, ...)
{
    va_list ap;
    int n;
    if (q->len >= q->cap)
        return;
    va_start(ap, fmt);
    n = vsnprintf(q->out + q->len, q->cap - q->len, fmt, ap);
    va_end(ap);
    q->len = n < 0 ? q->len : fmin(q->len + n, q->cap - 1);
}

static int fail(request *q, const char *code, const char *fmt, ...)
{
    va_list ap;
    char text[200];
    va_start(ap, fmt);
    vsnprintf(text, sizeof text, fmt, ap);
    va_end(ap);
    q->len = strcspn(q->out, " ");
    put(q, " err %s %s", code, text);
    return -1;
}

void trip_begin(trip_session *s, world *w, int robot, const char *lockdir)
{
    int d;
    memset(s, 0, sizeof *s);
    s->w = w;
    s->robot = robot;
    s->lockdir = lockdir;
    for (d = 0; d < DEVICES; d++)
        s->lock[d] = -1;
}

static void release(trip_session *s, int d)
{
    if (s->lock[d] >= 0) {
        close(s->lock[d]);      /* closing the file drops the flock */
        s->lock[d] = -1;
        /* A base let go, or whose client died, stops, as a B14's own
         * watchdog stops it when its controller falls silent. */
        if (d == BASE)
            robot_stop(s->w, s->robot);
    }
    if (d == SONAR)
        s->stream = 0;
}

void trip_end(trip_session *s)
{
    int d;
    for (d = 0; d < DEVICES; d++)
        release(s, d);
}

static int device_of(const char *name)
{
    int d;
    for (d = 0; d < DEVICES; d++)
        if (strcmp(name, device_names[d]) == 0)
            return d;
    return -1;
}

static int acquire(request *q, int d)
{
    trip_session *s = q->s;
    char path[4096];
    int fd;
    if (s->lock[d] >= 0)
        return 0;
    snprintf(path, sizeof path, "%s/%s.%s.lock", s->lockdir, q->w->robots[q->r].name, device_names[d]);
    fd = open(path, O_RDWR | O_CREAT | O_CLOEXEC, 0644);
    if (fd < 0)
        return fail(q, "held", "%s cannot be locked: %s", device_names[d], strerror(errno));
    if (flock(fd, LOCK_EX | LOCK_NB) < 0) {
        close(fd);
        return fail(q, "held", "%s is held by another client", device_names[d]);
    }
    s->lock[d] = fd;
    return 0;
}

/* ---- device commands ------------------------------------------------- */

static void put_ranges(request *q, const double *r, int n)
{
    int i;
    for (i = 0; i < n; i++)
        put(q, " %.0f", r[i]);
}

static void put_flags(request *q, const int *f, int n)
{
    int i;
    for (i = 0; i < n; i++)
        put(q, " %d", f[i]);
}

static int base_vel(request *q) { robot_velocity(q->w, q->r, q->arg[0], q->arg[1]); return 0; }
static int base_translate(request *q) { robot_translate(q->w, q->r, q->arg[0]); return 0; }
static int base_rotate(request *q) { robot_rotate(q->w, q->r, q->arg[0]); return 0; }
static int base_goto(request *q) { robot_goto(q->w, q->r, q->arg[0], q->arg[1]); return 0; }
static int base_stop(request *q) { robot_stop(q->w, q->r); return 0; }
static int base_set_position(request *q) { robot_set_position(q->w, q->r, q->arg[0], q->arg[1]); return 0; }
static int base_set_heading(request *q) { robot_set_heading(q->w, q->r, q->arg[0]); return 0; }

/* An angle in (-180, 180] with `digits` decimals.  The range must hold for
 * the text, not only for the number: wrap180 keeps -179.999 as it is, and
 * that prints as -180.00, which is 180; and a hair below 0 prints as -0.0,
 * which is 0. */
static void put_angle(request *q, double a, int digits)
{
    char text[32];
    snprintf(text, sizeof text, "%.*f", digits, a);
    if (strspn(text, "-0.") == strlen(text) && text[0] == '-')
        put(q, " %s", text + 1);
    else if (strncmp(text, "-180.", 5) == 0 && strspn(text + 5, "0") == strlen(text + 5))
        put(q, " %s", text + 1);
    else
        put(q, " %s", text);
}

static void put_heading(request *q, double h)
{
    put_angle(q, h, 2);
}

static int base_reckon(request *q)
{
    pose p = robot_reckon(q->w, q->r);
    put(q, " %.1f %.1f", p.x, p.y);
    put_heading(q, p.heading);
    return 0;
}

/* The end of a motion, as base await answers it: the pose and whether
 * the base stalled. */
static void put_motion_end(request *q)
{
    base_reckon(q);
    put(q, " %d", q->w->robots[q->r].m.stalled);
}

/* base await: answered at once when the base is idle, else once its motion
 * is over (trip_event), so that a client waits for the end of a motion
 * without asking again and again, and other requests go on meanwhile. */
static int base_await(request *q)
{
    long *free_slot = NULL;
    int i;
    if (q->w->robots[q->r].m.kind == IDLE) {
        put_motion_end(q);
        return 0;
    }
    for (i = 0; i < MAX_AWAITS && !free_slot; i++)
        if (q->s->awaits[i] == 0)
            free_slot = &q->s->awaits[i];
    if (!free_slot)
        return fail(q, "busy", "%d awaits are already pending", MAX_AWAITS);
    *free_slot = strtol(q->word[0], NULL, 10);
    q->deferred = 1;
    return 0;
}

static int base_status(request *q)
{
    const robot *r = &q->w->robots[q->r];
    base_reckon(q);
    put(q, " %.0f %.1f %d %d", r->v, r->w, r->m.kind != IDLE, r->m.stalled);
    return 0;
}

static int sonar_start(request *q) { robot_sonar_on(q->w, q->r, 1); return 0; }
static int sonar_stop(request *q) { robot_sonar_on(q->w, q->r, 0); return 0; }

static int sonar_read(request *q)
{
    const robot *r = &q->w->robots[q->r];
    if (!r->sonar_fired)
        robot_sonar_fire(q->w, q->r);
    put_ranges(q, r->sonar, SONARS);
    return 0;
}

static int sonar_stream(request *q)
{
    if (strcmp(q->word[3], "on") != 0 && strcmp(q->word[3], "off") != 0)
        return fail(q, "args", "sonar stream takes on or off");
    q->s->stream = strcmp(q->word[3], "on") == 0;
    q->s->streamed = q->w->robots[q->r].sonar_seq;
    return 0;
}

static int ir_read(request *q)
{
    double r[IRS];
    robot_ir(q->w, q->r, r);
    put_ranges(q, r, IRS);
    return 0;
}

static int fiducial_read(request *q)
{
    fiducial f[FIDUCIALS];
    int n = robot_fiducials(q->w, q->r, f, FIDUCIALS), i;
    put(q, " %d", n);
    for (i = 0; i < n; i++) {
        put(q, " %d %.0f", f[i].id, f[i].range);
        put_angle(q, f[i].bearing, 1);
        put_angle(q, f[i].orientation, 1);
    }
    return 0;
}

static int bumpers_read(request *q)
{
    int b[BUMPERS], s[SKIRTS];
    robot_contacts(q->w, q->r, b, s);
    put_flags(q, b, BUMPERS);
    return 0;
}

static int skirt_read(request *q)
{
    int b[BUMPERS], s[SKIRTS];
    robot_contacts(q->w, q->r, b, s);
    put_flags(q, s, SKIRTS);
    return 0;
}

static int button_index(request *q)
{
    double i = q->arg[0];
    if (i != floor(i) || i < 0 || i >= BUTTONS)
        return fail(q, "args", "button index must be 0 to %d", BUTTONS - 1);
    return (int)i;
}

static int buttons_read(request *q)
{
    int b[BUTTONS];
    robot_take_buttons(q->w, q->r, b);
    put_flags(q, b, BUTTONS);
    return 0;
}

static int buttons_press(request *q)
{
    int i = button_index(q);
    if (i >= 0)
        robot_button(q->w, q->r, i, 1);
    return i < 0 ? -1 : 0;
}

static int buttons_release(request *q)
{
    int i = button_index(q);
    if (i >= 0)
        robot_button(q->w, q->r, i, 0);
    return i < 0 ? -1 : 0;
}

static int lights_set(request *q)
{
    int i;
    for (i = 0; i < LIGHTS; i++)
        if (q->arg[i] != 0 && q->arg[i] != 1)
            return fail(q, "args", "lights take four 0 or 1");
    for (i = 0; i < LIGHTS; i++)
        robot_light(q->w, q->r, i, (int)q->arg[i]);
    return 0;
}

static int lights_read(request *q)
{
    put_flags(q, q->w->robots[q->r].lights, LIGHTS);
    return 0;
}

static int speech_say(request *q)
{
    robot_say(q->w, q->r, q->rest, q->restlen);
    return 0;
}

static int battery_read(request *q)
{
    const robot *r = &q->w->robots[q->r];
    put(q, " %.2f %d", r->battery, r->tethered);
    return 0;
}

static int battery_tether(request *q)
{
    if (q->arg[0] != 0 && q->arg[0] != 1)
        return fail(q, "args", "battery tether takes 0 or 1");
    robot_tether(q->w, q->r, (int)q->arg[0]);
    return 0;
}

/* nargs: numbers after DEVICE COMMAND; -1: words checked by the handler,
 * -2: free text.  needs_open is 0 only for what a finger on the robot does. */
static const struct command {
    int device;
    const char *name;
    int nargs, needs_open;
    int (*run)(request *);
} commands[] = {
    { BASE, "vel", 2, 1, base_vel },
    { BASE, "translate", 1, 1, base_translate },
    { BASE, "rotate", 1, 1, base_rotate },
    { BASE, "goto", 2, 1, base_goto },
    { BASE, "stop", 0, 1, base_stop },
    { BASE, "status", 0, 1, base_status },
    { BASE, "reckon", 0, 1, base_reckon },
    { BASE, "await", 0, 1, base_await },
    { BASE, "set-position", 2, 1, base_set_position },
    { BASE, "set-heading", 1, 1, base_set_heading },
    { SONAR, "start", 0, 1, sonar_start },
    { SONAR, "stop", 0, 1, sonar_stop },
    { SONAR, "read", 0, 1, sonar_read },
    { SONAR, "stream", -1, 1, sonar_stream },
    { IR, "read", 0, 1, ir_read },
    { BUMPERS_DEV, "read", 0, 1, bumpers_read },
    { SKIRT, "read", 0, 1, skirt_read },
    { BUTTONS_DEV, "read", 0, 1, buttons_read },
    { BUTTONS_DEV, "press", 1, 0, buttons_press },
    { BUTTONS_DEV, "release", 1, 0, buttons_release },
    { LIGHTS_DEV, "set", 4, 1, lights_set },
    { LIGHTS_DEV, "read", 0, 1, lights_read },
    { SPEECH, "say", -2, 1, speech_say },
    { BATTERY, "read", 0, 1, battery_read },
    { BATTERY, "tether", 1, 1, battery_tether },
    { FIDUCIAL, "read", 0, 1, fiducial_read },
};

static int numbers(request *q, int n)
{
    int i;
    if (q->nwords - 3 != n)
        return fail(q, "args", "%s %s takes %d number%s", q->word[1], q->word[2], n, n == 1 ? "" : "s");
    for (i = 0; i < n; i++) {
        char *end;
        q->arg[i] = strtod(q->word[3 + i], &end);
        if (*end || end == q->word[3 + i] || !isfinite(q->arg[i]))
            return fail(q, "args", "%s is not a number", q->word[3 + i]);
    }
    return 0;
}

static int device_command(request *q, int d)
{
    size_t i;
    if (q->nwords < 3)
        return fail(q, "args", "%s needs a command", device_names[d]);
    for (i = 0; i < sizeof commands / sizeof commands[0]; i++) {
        const struct command *c = &commands[i];
        if (c->device != d || strcmp(c->name, q->word[2]) != 0)
            continue;
        if (c->needs_open && q->s->lock[d] < 0)
            return fail(q, "not-open", "open %s first", device_names[d]);
        if (c->nargs == -1 && q->nwords != 4)
            return fail(q, "args", "%s %s takes one word", device_names[d], c->name);
        if (c->nargs >= 0 && numbers(q, c->nargs) < 0)
            return -1;
        return c->run(q);
    }
    return fail(q, "unknown", "%s has no command %.40s", device_names[d], q->word[2]);
}

static int connection_command(request *q)
{
    const char *verb = q->word[1];
    int d = q->nwords == 3 ? device_of(q->word[2]) : -1;
    if (strcmp(verb, "ping") == 0 && q->nwords == 2) {
        put(q, " pong");
    } else if (strcmp(verb, "who") == 0 && q->nwords == 2) {
        put(q, " %s b14-sim", q->w->robots[q->r].name);
    } else if (strcmp(verb, "time") == 0 && q->nwords == 2) {
        put(q, " %.0f", world_time(q->w) * 1000);
    } else if ((strcmp(verb, "open") == 0 || strcmp(verb, "close") == 0) && d < 0) {
        return fail(q, q->nwords == 3 ? "unknown" : "args", "%s takes one device name", verb);
    } else if (strcmp(verb, "open") == 0) {
        return acquire(q, d);
    } else if (strcmp(verb, "close") == 0) {
        release(q->s, d);
    } else if ((d = device_of(verb)) >= 0) {
        return device_command(q, d);
    } else {
        return fail(q, "unknown", "no command or device %.40s", verb);
    }
    return 0;
}

/* Split on spaces into at most MAX_WORDS words. */
static void split(request *q, char *text)
{
    char *p = text;
    q->nwords = 0;
    while (*p && q->nwords < MAX_WORDS) {
        while (*p == ' ')
            p++;
        if (!*p)
            break;
        q->word[q->nwords++] = p;
        p += strcspn(p, " ");
        if (*p)
            *p++ = 0;
    }
    if (q->nwords == MAX_WORDS && *p)
        q->nwords = MAX_WORDS + 1;  /* too many: no command takes so many */
}

static int valid_tag(const char *t)
{
    size_t n = strspn(t, "0123456789");
    return n >= 1 && n <= 9 && t[n] == 0 && strtol(t, NULL, 10) != 0;
}

size_t trip_handle(trip_session *s, const char *req, size_t n, char *out, size_t cap)
{
    request q;
    char *text = xmalloc(n + 1), *say;
    memset(&q, 0, sizeof q);
    q.s = s;
    q.w = s->w;
    q.r = s->robot;
    q.out = out;
    q.cap = cap;
    memcpy(text, req, n);
    text[n] = 0;
    /* speech carries the raw rest of the payload, NULs and all */
    say = strstr(text, " speech say ");
    split(&q, text);
    if (q.nwords < 2 || !valid_tag(q.word[0])) {
        put(&q, "0");
        fail(&q, "syntax", "a request is TAG WORD ..., TAG a number 1 to 999999999");
    } else {
        put(&q, "%s ok", q.word[0]);
        if (say && q.nwords >= 3 && strcmp(q.word[1], "speech") == 0 && strcmp(q.word[2], "say") == 0) {
            q.rest = req + (say - text) + strlen(" speech say ");
            q.restlen = n - (q.rest - req);
            q.nwords = 3;
        } else if (q.nwords > MAX_WORDS) {
            fail(&q, "args", "too many words");
            free(text);
            return q.len;
        }
        connection_command(&q);
    }
    free(text);
    return q.deferred ? 0 : q.len;
}

/* The reply of one pending base await, once the base is idle; 0 if none. */
static size_t await_reply(request *q)
{
    int i;
    if (q->w->robots[q->r].m.kind != IDLE)
        return 0;
    for (i = 0; i < MAX_AWAITS; i++)
        if (q->s->awaits[i] != 0) {
            put(q, "%ld ok", q->s->awaits[i]);
            put_motion_end(q);
            q->s->awaits[i] = 0;
            return q->len;
        }
    return 0;
}

size_t trip_event(trip_session *s, char *out, size_t cap)
{
    const robot *r = &s->w->robots[s->robot];
    request q;
    memset(&q, 0, sizeof q);
    q.s = s;
    q.w = s->w;
    q.r = s->robot;
    q.out = out;
    q.cap = cap;
    if (await_reply(&q) > 0)
        return q.len;
    if (!s->stream || r->sonar_seq == s->streamed)
        return 0;
    s->streamed = r->sonar_seq;
    put(&q, "0 sonar");
    put_ranges(&q, r->sonar, SONARS);
    return q.len;
}
