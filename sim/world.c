#include <math.h>
#include <pthread.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "world.h"
#include "alloc.h"

static const double RAD = M_PI / 180;

double wrap180(double a)
{
    a = fmod(a, 360);
    if (a > 180)
        a -= 360;
    if (a <= -180)
        a += 360;
    return a;
}

static double clip(double v, double limit)
{
    return v > limit ? limit : v < -limit ? -limit : v;
}

/* splitmix64: one stream per robot, so readings do not depend on which
 * thread took them or in which order robots fired */
static uint64_t next_random(uint64_t *s)
{
    uint64_t z = (*s += 0x9e3779b97f4a7c15ULL);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
    return z ^ (z >> 31);
}

/* Two independent standard normal numbers (Box-Muller). */
static void gaussians(uint64_t *s, double *a, double *b)
{
    double u = ((next_random(s) >> 11) + 0.5) / 9007199254740992.0;
    double v = (next_random(s) >> 11) / 9007199254740992.0;
    double m = sqrt(-2 * log(u));
    *a = m * cos(2 * M_PI * v);
    *b = m * sin(2 * M_PI * v);
}

/* One robot's reading in the making: its pose when the sonars fired, and
 * the state its last reading left, which this one replaces. */
typedef struct {
    int robot;
    pose at;
    sonar_state ss;
    double reading[SONARS];
} shot;

typedef struct {
    struct world *w;
    sense_scratch *scratch;
} taker;

/* The round of readings under way (see fire_due_sonars). */
struct round {
    shot *shots;
    int n, step;
    const sense *grid;          /* the world's grid, or snapshot when helped */
    sense *snapshot;
    atomic_int next;
    atomic_long reused;
    pthread_t helper;
    int helped;                 /* a helper thread is at work on it */
    taker helping;              /* what the helper was given */
};

/* The grid covers every wall, box and robot with a margin. */
static sense *make_sense(const lab *l)
{
    double x0 = INFINITY, y0 = INFINITY, x1 = -INFINITY, y1 = -INFINITY, m = 1000;
    int i;
#define COVER(x, y) (x0 = fmin(x0, x), y0 = fmin(y0, y), x1 = fmax(x1, x), y1 = fmax(y1, y))
    for (i = 0; i < l->nwalls; i++) {
        COVER(l->walls[i].x1, l->walls[i].y1);
        COVER(l->walls[i].x2, l->walls[i].y2);
    }
    for (i = 0; i < l->nboxes; i++)
        COVER(l->boxes[i].x, l->boxes[i].y);
    for (i = 0; i < l->nrobots; i++)
        COVER(l->robots[i].x, l->robots[i].y);
#undef COVER
    if (x0 > x1) {
        x0 = y0 = -5000;
        x1 = y1 = 5000;
    }
    return sense_new(x0 - m, y0 - m, x1 + m, y1 + m, 1500);
}

enum { MAX_RAYS = SENSE_MAX_RAYS };

typedef struct { double angle; int sonar; } ray;

static int by_angle(const void *a, const void *b)
{
    double x = ((const ray *)a)->angle, y = ((const ray *)b)->angle;
    return (x > y) - (x < y);
}

/* The rays' offsets from the heading, counter-clockwise as sense_fan wants
 * them: the sonar cones' rays (and which sonar each belongs to), then the
 * ir ring. */
static void make_fan(world *w)
{
    const b14_params *p = &w->lab->b14;
    int n = p->sonar_rays, i, j, k = 0, rays = SONARS * n;
    ray r[MAX_RAYS];
    w->fan = xmalloc(2 * (rays + IRS) * sizeof *w->fan);
    w->fan_sonar = xmalloc(rays * sizeof *w->fan_sonar);
    for (i = 0; i < SONARS; i++)
        for (j = 0; j < n; j++, k++) {
            double off = 22.5 * i + (n == 1 ? 0 : p->sonar_cone * ((double)j / (n - 1) - 0.5));
            r[k] = (ray){ fmod(off + 360, 360), i };
        }
    qsort(r, rays, sizeof r[0], by_angle);
    for (k = 0; k < rays + IRS; k++) {
        double off = (k < rays ? r[k].angle : 22.5 * (k - rays)) * RAD;
        w->fan[2 * k] = cos(off);
        w->fan[2 * k + 1] = sin(off);
        if (k < rays)
            w->fan_sonar[k] = r[k].sonar;
    }
}

world *world_new(lab *l)
{
    world *w = xcalloc(1, sizeof *w);
    int i;
    w->lab = l;
    w->dt = 1.0 / l->step_hz;
    w->threads = 2;
    w->phys = physics_new();
    w->sense = make_sense(l);
    make_fan(w);
    for (i = 0; i < l->nwalls; i++) {
        const lab_wall *a = &l->walls[i];
        physics_add_wall(w->phys, a->x1, a->y1, a->x2, a->y2, a->thick);
        sense_add_wall(w->sense, a->x1, a->y1, a->x2, a->y2, a->thick);
    }
    for (i = 0; i < l->nboxes; i++) {
        const lab_box *b = &l->boxes[i];
        pose at = { b->x, b->y, b->heading };
        physics_add_box(w->phys, at, b->w, b->d, b->mass, l->friction);
        sense_place_box(w->sense, sense_add_box(w->sense, b->w, b->d), at);
    }
    w->robots = xcalloc(l->nrobots ? l->nrobots : 1, sizeof *w->robots);
    w->nrobots = l->nrobots;
    for (i = 0; i < l->nrobots; i++) {
        const lab_robot *c = &l->robots[i];
        robot *r = &w->robots[i];
        strcpy(r->name, c->name);
        r->at = r->before = (pose){ c->x, c->y, c->heading };
        r->body = physics_add_robot(w->phys, r->at, l->b14.radius, l->b14.mass);
        r->circle = sense_add_circle(w->sense, l->b14.radius);
        sense_place_circle(w->sense, r->circle, c->x, c->y);
        r->battery = c->battery;
        r->tethered = c->tethered;
        r->ss.rng = l->seed * 1000003ULL + i;
        r->ss.step = -1;
    }
    sense_refile(w->sense, 0);
    w->round = xcalloc(1, sizeof *w->round);
    w->round->shots = xmalloc((w->nrobots + 1) * sizeof *w->round->shots);
    return w;
}

void world_free(world *w)
{
    world_sync(w);
    if (w->round->snapshot)
        sense_free(w->round->snapshot);
    free(w->round->shots);
    free(w->round);
    physics_free(w->phys);
    sense_free(w->sense);
    sense_scratch_free(&w->scratch[0]);
    sense_scratch_free(&w->scratch[1]);
    free(w->fan);
    free(w->fan_sonar);
    free(w->robots);
    free(w);
}

double world_time(const world *w)
{
    return w->step * w->dt;
}

/* ---- motion ---------------------------------------------------------- */

static void start(robot *r, enum motion_kind kind)
{
    memset(&r->m, 0, sizeof r->m);
    r->m.kind = kind;
}

void robot_velocity(world *w, int i, double tv, double rv)
{
    robot *r = &w->robots[i];
    start(r, VELOCITY);
    r->m.tv = clip(tv, w->lab->b14.max_speed);
    r->m.rv = clip(rv, w->lab->b14.max_turn);
}

void robot_translate(world *w, int i, double d)
{
    start(&w->robots[i], TRANSLATE);
    w->robots[i].m.left = d;
}

void robot_rotate(world *w, int i, double a)
{
    start(&w->robots[i], ROTATE);
    w->robots[i].m.left = a;
}

void robot_goto(world *w, int i, double x, double y)
{
    robot *r = &w->robots[i];
    double c = cos(-r->odth * RAD), s = sin(-r->odth * RAD);
    double ux = x - r->odx, uy = y - r->ody;
    start(r, GOTO);
    r->m.gx = ux * c - uy * s;
    r->m.gy = ux * s + uy * c;
    r->m.turning = 1;
}

void robot_stop(world *w, int i)
{
    start(&w->robots[i], IDLE);
}

pose robot_reckon(const world *w, int i)
{
    const robot *r = &w->robots[i];
    double c = cos(r->odth * RAD), s = sin(r->odth * RAD);
    return (pose){ r->at.x * c - r->at.y * s + r->odx, r->at.x * s + r->at.y * c + r->ody,
                   wrap180(r->at.heading + r->odth) };
}

void robot_set_position(world *w, int i, double x, double y)
{
    robot *r = &w->robots[i];
    pose now = robot_reckon(w, i);
    r->odx += x - now.x;
    r->ody += y - now.y;
}

void robot_set_heading(world *w, int i, double h)
{
    robot *r = &w->robots[i];
    pose now = robot_reckon(w, i);
    r->odth = h - r->at.heading;
    robot_set_position(w, i, now.x, now.y);
}

/* Proportional approach with a floor, so a motion ends rather than creeps. */
static double approach(double left, double gain, double floor, double limit)
{
    double v = fmax(fabs(left) * gain, floor);
    return copysign(fmin(v, limit), left);
}

/* What the wheels do this step, from the motion under way. */
static void control(const b14_params *p, robot *r)
{
    motion *m = &r->m;
    double dist, bearing;
    r->v = r->w = 0;
    switch (m->kind) {
    case IDLE:
        return;
    case VELOCITY:
        r->v = m->tv;
        r->w = m->rv;
        return;
    case TRANSLATE:
        if (fabs(m->left) < 0.5)
            break;
        r->v = approach(m->left, 3, 5, p->speed);
        return;
    case ROTATE:
        if (fabs(m->left) < 0.05)
            break;
        r->w = approach(m->left, 3, 1, p->turn);
        return;
    case GOTO:
        dist = hypot(m->gx - r->at.x, m->gy - r->at.y);
        bearing = wrap180(atan2(m->gy - r->at.y, m->gx - r->at.x) / RAD - r->at.heading);
        if (m->turning && dist > 30 && fabs(bearing) > 0.2) {
            r->w = approach(bearing, 3, 1, p->turn);
            return;
        }
        m->turning = 0;
        /* close in along the heading; steering so near the goal would only
         * chase the bearing round, and the lateral error is already tiny */
        dist *= cos(bearing * RAD);
        if (fabs(dist) < 0.5)
            break;
        r->v = approach(dist, 3, 5, p->speed);
        if (hypot(m->gx - r->at.x, m->gy - r->at.y) > 60)
            r->w = clip(3 * bearing, p->turn);
        return;
    }
    start(r, IDLE);
}

/* Progress of the motion under way, from where the body actually went. */
static void account(world *w, robot *r)
{
    double dx = r->at.x - r->before.x, dy = r->at.y - r->before.y;
    double along = dx * cos(r->before.heading * RAD) + dy * sin(r->before.heading * RAD);
    double turned = wrap180(r->at.heading - r->before.heading);
    motion *m = &r->m;
    if (m->kind == TRANSLATE)
        m->left -= along;
    else if (m->kind == ROTATE)
        m->left -= turned;
    if (fabs(r->v) > 1 && fabs(along) < 0.2 * fabs(r->v) * w->dt)
        m->stuck += w->dt;
    else
        m->stuck = 0;
    if (m->stuck > 2) {
        if (m->kind == VELOCITY) {
            m->stalled = 1;
        } else {
            start(r, IDLE);
            r->m.stalled = 1;
        }
    }
}

static void battery(const b14_params *p, robot *r, double dt)
{
    int moving = fabs(r->v) > 0 || fabs(r->w) > 0;
    r->battery -= (moving ? p->drain : p->idle) * dt;
    if (r->tethered)
        r->battery += p->charge * dt;
    r->battery = fmin(fmax(r->battery, p->v_low), p->v_high);
}

/* ---- sensing --------------------------------------------------------- */

/* Distances from the skin along n rays of the fan, starting at ray first,
 * cast in `grid` from a robot at `at`. */
static void cast(const world *w, const sense *grid, const robot *r, pose at, sense_scratch *sc,
                 int first, int n, double range, double *t)
{
    double c = cos(at.heading * RAD), s = sin(at.heading * RAD);
    double dx[MAX_RAYS] = { 0 }, dy[MAX_RAYS] = { 0 };  /* all set below; gcc cannot tell */
    double radius = w->lab->b14.radius;
    const double *fan = w->fan + 2 * first;
    int k;
    for (k = 0; k < n; k++) {
        dx[k] = c * fan[2 * k] - s * fan[2 * k + 1];
        dy[k] = s * fan[2 * k] + c * fan[2 * k + 1];
    }
    if (w->plain) {
        for (k = 0; k < n; k++)
            t[k] = physics_ray(w->phys, r->body, at.x + radius * dx[k], at.y + radius * dy[k],
                               dx[k], dy[k], range);
        return;
    }
    /* rays from the centre are the same lines as rays from the skin */
    sense_fan(grid, sc, r->circle, at.x, at.y, dx, dy, n, range + radius, t);
    for (k = 0; k < n; k++)
        t[k] = greater(t[k] - radius, 0);
}

/* Every sonar cone, noiseless: the nearest of its rays. */
static void sonar_geometry(const world *w, const sense *grid, shot *h, sense_scratch *sc)
{
    const b14_params *p = &w->lab->b14;
    int rays = SONARS * p->sonar_rays, i, k;
    double t[MAX_RAYS], reach = 0;
    cast(w, grid, &w->robots[h->robot], h->at, sc, 0, rays, p->sonar_max, t);
    for (i = 0; i < SONARS; i++)
        h->ss.geo[i] = p->sonar_max;
    for (k = 0; k < rays; k++) {
        i = w->fan_sonar[k];
        h->ss.geo[i] = lesser(h->ss.geo[i], t[k]);
    }
    for (i = 0; i < SONARS; i++)
        reach = greater(reach, h->ss.geo[i]);
    h->ss.reach = reach + p->radius;
}

/* The last geometry still holds if the robot has not moved and nothing
 * has moved within its reach since. */
static int reusable(const world *w, const sense *grid, const shot *h)
{
    return !w->plain && h->ss.step >= 0 && h->ss.at.x == h->at.x && h->ss.at.y == h->at.y
        && h->ss.at.heading == h->at.heading
        && sense_still(grid, h->at.x, h->at.y, h->ss.reach, h->ss.step + 1);
}

/* One reading at `step`: geometry (fresh or reused) plus this reading's
 * noise.  Touches nothing but the shot, so helpers may take shots at once. */
static int take(const world *w, const sense *grid, int step, shot *h, sense_scratch *sc)
{
    const b14_params *p = &w->lab->b14;
    int i, reuse = reusable(w, grid, h);
    double noise[SONARS];
    if (!reuse)
        sonar_geometry(w, grid, h, sc);
    h->ss.at = h->at;
    h->ss.step = step;
    for (i = 0; i < SONARS; i += 2)
        gaussians(&h->ss.rng, &noise[i], &noise[i + 1]);
    for (i = 0; i < SONARS; i++) {
        double g = h->ss.geo[i];
        if (g < p->sonar_max)
            g += p->sonar_noise * noise[i];
        h->reading[i] = lesser(greater(g, p->sonar_min), p->sonar_max);
    }
    return reuse;
}

static shot aim(const world *w, int i)
{
    shot h;
    h.robot = i;
    h.at = w->robots[i].at;
    h.ss = w->robots[i].ss;
    return h;
}

/* The reading becomes the robot's. */
static void publish(world *w, const shot *h)
{
    robot *r = &w->robots[h->robot];
    r->ss = h->ss;
    memcpy(r->sonar, h->reading, sizeof r->sonar);
    r->sonar_seq++;
    r->sonar_fired = 1;
    if (w->observer.sonar)
        w->observer.sonar(w->observer.data, w, h->robot);
}

void robot_sonar_fire(world *w, int i)
{
    shot h;
    world_sync(w);
    h = aim(w, i);
    w->reused += take(w, w->sense, w->step, &h, &w->scratch[0]);
    w->scans++;
    publish(w, &h);
}

void robot_ir(world *w, int i, double out[IRS])
{
    const robot *r = &w->robots[i];
    cast(w, w->sense, r, r->at, &w->scratch[0], SONARS * w->lab->b14.sonar_rays, IRS,
         w->lab->b14.ir_range, out);
}

void robot_contacts(const world *w, int i, int bumpers[BUMPERS], int skirt[SKIRTS])
{
    const robot *r = &w->robots[i];
    double dirs[16];
    int n = physics_robot_touches(w->phys, r->body, dirs, 16), k;
    memset(bumpers, 0, BUMPERS * sizeof(int));
    memset(skirt, 0, SKIRTS * sizeof(int));
    for (k = 0; k < n; k++) {
        double rel = wrap180(dirs[k] - r->at.heading);
        int s = (int)floor(wrap180(rel + 30) / 60 + 6) % 6;
        skirt[s] = 1;
        if (fabs(rel) < 90)
            bumpers[(int)fmin(floor((rel + 90) / 15), BUMPERS - 1)] = 1;
    }
}

void robot_sonar_on(world *w, int i, int on) { w->robots[i].sonar_on = on; }
void robot_button(world *w, int i, int button, int pressed) { w->robots[i].buttons[button] = pressed; }
void robot_light(world *w, int i, int light, int on) { w->robots[i].lights[light] = on; }
void robot_tether(world *w, int i, int on) { w->robots[i].tethered = on; }

void robot_take_buttons(world *w, int i, int out[BUTTONS])
{
    memcpy(out, w->robots[i].buttons, sizeof w->robots[i].buttons);
    memset(w->robots[i].buttons, 0, sizeof w->robots[i].buttons);
}

/* How far along the ray from (x, y) along the unit (dx, dy) it enters the
 * box at `at`, w by d: 0 from inside, -1 when it misses (slabs, in the
 * box's own frame). */
static double box_entry(pose at, double w, double d, double x, double y, double dx, double dy)
{
    double c = cos(at.heading * RAD), s = sin(at.heading * RAD);
    double o[2] = { (x - at.x) * c + (y - at.y) * s, -(x - at.x) * s + (y - at.y) * c };
    double u[2] = { dx * c + dy * s, -dx * s + dy * c }, half[2] = { w / 2, d / 2 };
    double in = 0, out = INFINITY, t1, t2;
    int k;
    for (k = 0; k < 2; k++) {
        if (fabs(u[k]) < 1e-12) {
            if (fabs(o[k]) > half[k])
                return -1;
            continue;
        }
        t1 = (-half[k] - o[k]) / u[k];
        t2 = (half[k] - o[k]) / u[k];
        in = greater(in, lesser(t1, t2));
        out = lesser(out, greater(t1, t2));
    }
    return in <= out ? in : -1;
}

/* Whether robot r sees box b at `at` along the line to (tx, ty): the
 * first thing the line meets is this box's edge. */
static int in_sight(world *w, const robot *r, const lab_box *b, pose at, double tx, double ty)
{
    double dx = tx - r->at.x, dy = ty - r->at.y, d = hypot(dx, dy), entry, first;
    if (d < 1)
        return 1;
    dx /= d;
    dy /= d;
    entry = box_entry(at, b->w, b->d, r->at.x, r->at.y, dx, dy);
    if (entry < 0)
        return 0;
    sense_fan(w->sense, &w->scratch[0], r->circle, r->at.x, r->at.y, &dx, &dy, 1, d, &first);
    return first >= entry - 1;
}

int robot_fiducials(world *w, int i, fiducial *out, int max)
{
    const robot *r = &w->robots[i];
    const b14_params *p = &w->lab->b14;
    int b, n = 0, k;
    for (b = 0; b < w->lab->nboxes; b++) {
        const lab_box *box = &w->lab->boxes[b];
        pose at = physics_box_pose(w->phys, b);
        double d = hypot(at.x - r->at.x, at.y - r->at.y);
        double bearing = wrap180(atan2(at.y - r->at.y, at.x - r->at.x) / RAD - r->at.heading);
        double c = cos(at.heading * RAD), s = sin(at.heading * RAD), inset = 0.9;
        int seen = 0, corner;
        fiducial f;
        if (d > p->fiducial_range || fabs(bearing) > p->fiducial_fov / 2)
            continue;
        seen = in_sight(w, r, box, at, at.x, at.y);
        /* a box whose centre is hidden may still show a corner */
        for (corner = 0; corner < 4 && !seen; corner++) {
            double u = (corner & 1 ? 0.5 : -0.5) * box->w * inset;
            double v = (corner & 2 ? 0.5 : -0.5) * box->d * inset;
            seen = in_sight(w, r, box, at, at.x + u * c - v * s, at.y + u * s + v * c);
        }
        if (!seen)
            continue;
        f = (fiducial){ b, d, bearing, wrap180(at.heading - r->at.heading) };
        /* keep the nearest max, nearest first */
        for (k = n < max ? n++ : max; k > 0 && out[k - 1].range > d; k--)
            if (k < max)
                out[k] = out[k - 1];
        if (k < max)
            out[k] = f;
    }
    return n;
}

void robot_say(world *w, int i, const char *text, size_t n)
{
    char clean[512];
    size_t k;
    for (k = 0; k < n && k < sizeof clean - 1; k++)
        clean[k] = text[k] >= 0x20 && text[k] < 0x7f ? text[k] : '?';
    clean[k] = 0;
    fprintf(stderr, "b14: %.3f %s says: %s\n", world_time(w), w->robots[i].name, clean);
    if (w->observer.say)
        w->observer.say(w->observer.data, w, i, clean);
}

/* ---- the step -------------------------------------------------------- */

enum { CLAIM = 8 };

/* Take the readings of a round, a few robots at a time, as long as any are
 * left unclaimed: on a machine whose other core is busy elsewhere, the
 * caller simply does more of the round instead of waiting for a slow
 * helper. */
static void *take_claimed(void *arg)
{
    taker *me = arg;
    struct round *o = me->w->round;
    long reused = 0;
    int first, k;
    while ((first = atomic_fetch_add(&o->next, CLAIM)) < o->n)
        for (k = first; k < first + CLAIM && k < o->n; k++)
            reused += take(me->w, o->grid, o->step, &o->shots[k], me->scratch);
    atomic_fetch_add(&o->reused, reused);
    return NULL;
}

static void finish_round(world *w)
{
    struct round *o = w->round;
    int k;
    for (k = 0; k < o->n; k++)
        publish(w, &o->shots[k]);
    w->scans += o->n;
    w->reused += atomic_load(&o->reused);
    o->n = 0;
}

void world_sync(world *w)
{
    struct round *o = w->round;
    taker mine = { w, &w->scratch[0] };
    if (!o->helped)
        return;
    take_claimed(&mine);
    pthread_join(o->helper, NULL);
    o->helped = 0;
    finish_round(w);
}

/* Started sonars fire together every step_hz / sonar_hz steps.  A round big
 * enough to share goes to a helper thread with a snapshot of the grid, so
 * that the steps until the next round overlap it. */
static void fire_due_sonars(world *w)
{
    int period = (int)fmax(1, round(w->lab->step_hz / w->lab->b14.sonar_hz)), i;
    struct round *o = w->round;
    taker mine = { w, &w->scratch[0] };
    if (w->step % period != 0)
        return;
    world_sync(w);
    for (i = 0; i < w->nrobots; i++)
        if (w->robots[i].sonar_on)
            o->shots[o->n++] = aim(w, i);
    o->step = w->step;
    atomic_init(&o->next, 0);
    atomic_init(&o->reused, 0);
    if (w->threads > 1 && !w->plain && o->n >= 4 * CLAIM) {
        o->snapshot = sense_snapshot(o->snapshot, w->sense);
        o->grid = o->snapshot;
        o->helping = (taker){ w, &w->scratch[1] };
        o->helped = pthread_create(&o->helper, NULL, take_claimed, &o->helping) == 0;
        if (o->helped)
            return;
    }
    o->grid = w->sense;
    take_claimed(&mine);
    finish_round(w);
}

void world_step(world *w)
{
    const b14_params *p = &w->lab->b14;
    int i;
    for (i = 0; i < w->nrobots; i++) {
        robot *r = &w->robots[i];
        control(p, r);
        physics_drive(w->phys, r->body, r->v, r->w);
    }
    physics_step(w->phys, w->dt);
    w->step++;
    for (i = 0; i < w->nrobots; i++) {
        robot *r = &w->robots[i];
        r->before = r->at;
        r->at = physics_robot_pose(w->phys, r->body);
        sense_place_circle(w->sense, r->circle, r->at.x, r->at.y);
        account(w, r);
        battery(p, r, w->dt);
    }
    for (i = 0; i < w->lab->nboxes; i++)
        sense_place_box(w->sense, i, physics_box_pose(w->phys, i));
    sense_refile(w->sense, w->step);
    fire_due_sonars(w);
    if (w->observer.step)
        w->observer.step(w->observer.data, w);
}
