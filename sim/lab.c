#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "lab.h"
#include "sexp.h"
#include "alloc.h"

void lab_defaults(lab *l)
{
    static const b14_params b14 = {
        .radius = 180, .mass = 70, .max_speed = 600, .max_turn = 120,
        .speed = 400, .turn = 60,
        .sonar_min = 150, .sonar_max = 6500, .sonar_cone = 25,
        .sonar_noise = 10, .sonar_hz = 10, .sonar_rays = 3,
        .ir_range = 600,
        .fiducial_range = 5000, .fiducial_fov = 180,
        .drain = 0.002, .idle = 0.0002, .charge = 0.01,
        .v_low = 10.0, .v_high = 14.0, .max_frame = 1024 };
    memset(l, 0, sizeof *l);
    l->port_base = 7100;
    strcpy(l->interface, "127.0.0.1");
    l->step_hz = 60;
    l->seed = 1;
    l->speed = 1;
    l->friction = 0.4;
    l->stall_timeout = 10;
    l->b14 = b14;
}

static void *grow(void *v, int n, size_t size)
{
    /* arrays grow by doubling; n is the count before adding one */
    if ((n & (n - 1)) == 0)
        v = xrealloc(v, (n ? 2 * n : 1) * size);
    return v;
}

int lab_add_robot(lab *l, const lab_robot *r)
{
    l->robots = grow(l->robots, l->nrobots, sizeof *r);
    l->robots[l->nrobots] = *r;
    return l->nrobots++;
}

void lab_add_wall(lab *l, double x1, double y1, double x2, double y2, double thick)
{
    lab_wall w = { x1, y1, x2, y2, thick };
    l->walls = grow(l->walls, l->nwalls, sizeof w);
    l->walls[l->nwalls++] = w;
}

void lab_add_box(lab *l, const lab_box *b)
{
    l->boxes = grow(l->boxes, l->nboxes, sizeof *b);
    l->boxes[l->nboxes++] = *b;
}

int lab_trip_port(const lab *l, const lab_robot *r)
{
    /* the port plan's trip offset (lib/murdoch/lab/file.scm) */
    return r->trip_port ? r->trip_port : l->port_base + 100 + r->aspace;
}

void lab_free(lab *l)
{
    free(l->robots);
    free(l->walls);
    free(l->boxes);
}

/* Numbers of a clause (NAME N1 N2 ...): how many of the first max were numbers. */
static int numbers(const sx *clause, double *out, int max)
{
    int i;
    for (i = 0; i < max; i++) {
        const sx *x = sx_nth(clause, i + 1);
        if (!x || x->kind != SX_NUMBER)
            break;
        out[i] = x->num;
    }
    return i;
}

static int bad(char *err, int errlen, const char *what, const char *name)
{
    snprintf(err, errlen, "lab: bad %s clause%s%s", what, name ? " in " : "", name ? name : "");
    return -1;
}

static int read_robot(lab *l, const sx *aspace, int index, const sx *robot,
                      char *err, int errlen)
{
    lab_robot r;
    const sx *name = sx_nth(aspace, 1), *c;
    double v[3] = { 0 };
    memset(&r, 0, sizeof r);
    if (!name || name->kind != SX_SYMBOL || strlen(name->text) >= sizeof r.name)
        return bad(err, errlen, "aspace name", NULL);
    strcpy(r.name, name->text);
    r.aspace = index;
    r.battery = 13.6;
    for (c = robot->head->next; c; c = c->next)
        if (sx_is(c->head, "ros2"))
            return 0;   /* a ROS 2 robot: its own trip server, not a B14 */
    for (c = robot->head->next; c; c = c->next) {
        const sx *arg = sx_nth(c, 1);
        if (sx_is(c->head, "pose") && numbers(c, v, 3) == 3) {
            r.x = v[0]; r.y = v[1]; r.heading = v[2];
        } else if (sx_is(c->head, "tethered") && arg && arg->kind == SX_BOOL) {
            r.tethered = (int)arg->num;
        } else if (sx_is(c->head, "battery") && numbers(c, v, 1) == 1) {
            r.battery = v[0];
        } else if (sx_is(c->head, "trip-port") && numbers(c, v, 1) == 1) {
            r.trip_port = (int)v[0];
        } else if (sx_is(c->head, "trip-host") && arg && arg->kind == SX_STRING) {
            /* where the robot's address space finds this server: the
             * server itself listens on the lab's interface */
        } else {
            return bad(err, errlen, "robot", r.name);
        }
    }
    lab_add_robot(l, &r);
    return 0;
}

static int read_world(lab *l, const sx *world, char *err, int errlen)
{
    const sx *c;
    double v[6] = { 0 };
    for (c = world->head->next; c; c = c->next) {
        int n = numbers(c, v, 6);
        if (c->kind != SX_LIST)
            return bad(err, errlen, "world", NULL);
        /* sizes and masses above 0, as lib/murdoch/lab/clauses.scm checks them */
        if (sx_is(c->head, "wall") && (n == 4 || (n == 5 && v[4] > 0))) {
            lab_add_wall(l, v[0], v[1], v[2], v[3], n == 5 ? v[4] : 50);
        } else if (sx_is(c->head, "box") && (n == 5 || (n == 6 && v[5] > 0))
                   && v[2] > 0 && v[3] > 0) {
            lab_box b = { v[0], v[1], v[2], v[3], v[4], n == 6 ? v[5] : 5 };
            lab_add_box(l, &b);
        } else if (sx_is(c->head, "friction") && n == 1) {
            l->friction = v[0];
        } else {
            return bad(err, errlen, "world", NULL);
        }
    }
    return 0;
}

static int read_simulator(lab *l, const sx *sim, char *err, int errlen)
{
    const sx *c;
    double v = 0;
    for (c = sim->head->next; c; c = c->next) {
        int n = numbers(c, &v, 1);
        if (sx_is(c->head, "step-hz") && n == 1 && v >= 1)
            l->step_hz = (int)v;
        else if (sx_is(c->head, "seed") && n == 1)
            l->seed = (unsigned long)v;
        else if (sx_is(c->head, "speed") && n == 1 && v > 0)
            l->speed = v;
        else if (sx_is(c->head, "stall-timeout") && n == 1 && v > 0)
            l->stall_timeout = v;
        else if (sx_is(c->head, "speed") && sx_is(sx_nth(c, 1), "fast"))
            l->speed = 0;
        else
            return bad(err, errlen, "simulator", NULL);
    }
    return 0;
}

static int read_b14(lab *l, const sx *b14, char *err, int errlen)
{
    static const struct { const char *name; size_t off; } one[] = {
#define P(n, f) { n, offsetof(b14_params, f) }
        P("radius", radius), P("mass", mass), P("max-speed", max_speed),
        P("max-turn", max_turn), P("speed", speed), P("turn-speed", turn),
        P("sonar-cone", sonar_cone), P("sonar-noise", sonar_noise),
        P("sonar-hz", sonar_hz), P("ir-range", ir_range),
        P("fiducial-range", fiducial_range),
        P("battery-drain", drain), P("battery-idle", idle),
        P("battery-charge", charge),
#undef P
    };
    b14_params *p = &l->b14;
    const sx *c;
    double v[2] = { 0, 0 };
    for (c = b14->head->next; c; c = c->next) {
        int n = numbers(c, v, 2);
        size_t i;
        for (i = 0; i < sizeof one / sizeof one[0]; i++)
            if (sx_is(c->head, one[i].name) && n == 1 && v[0] >= 0)
                break;
        if (i < sizeof one / sizeof one[0])
            *(double *)((char *)p + one[i].off) = v[0];
        else if (sx_is(c->head, "sonar-range") && n == 2 && v[0] < v[1]) {
            p->sonar_min = v[0]; p->sonar_max = v[1];
        } else if (sx_is(c->head, "battery-range") && n == 2 && v[0] < v[1]) {
            p->v_low = v[0]; p->v_high = v[1];
        } else if (sx_is(c->head, "fiducial-fov") && n == 1 && v[0] > 0 && v[0] <= 360) {
            p->fiducial_fov = v[0];
        } else if (sx_is(c->head, "sonar-rays") && n == 1 && v[0] >= 1 && v[0] <= 16)
            p->sonar_rays = (int)v[0];
        else if (sx_is(c->head, "max-frame") && n == 1 && v[0] >= 64 && v[0] <= 65536)
            p->max_frame = (int)v[0];
        else
            return bad(err, errlen, "b14", NULL);
    }
    return 0;
}

static int read_lab(lab *l, const sx *top, char *err, int errlen)
{
    const sx *c;
    int aspace = 0;
    double v = 0;
    if (top->kind != SX_LIST || !sx_is(top->head, "lab"))
        return bad(err, errlen, "top-level (lab NAME ...)", NULL);
    for (c = sx_nth(top, 2); c; c = c->next) {
        const sx *head = c->kind == SX_LIST ? c->head : NULL;
        int rc = 0;
        if (sx_is(head, "aspace")) {
            const sx *robot = sx_clause(c, "robot", NULL);
            if (robot)
                rc = read_robot(l, c, aspace, robot, err, errlen);
            aspace++;
        } else if (sx_is(head, "port-base") && numbers(c, &v, 1) == 1) {
            l->port_base = (int)v;
        } else if (sx_is(head, "interface") && sx_nth(c, 1)
                   && sx_nth(c, 1)->kind == SX_STRING
                   && strlen(sx_nth(c, 1)->text) < sizeof l->interface) {
            strcpy(l->interface, sx_nth(c, 1)->text);
        } else if (sx_is(head, "world")) {
            rc = read_world(l, c, err, errlen);
        } else if (sx_is(head, "simulator")) {
            rc = read_simulator(l, c, err, errlen);
        } else if (sx_is(head, "b14")) {
            rc = read_b14(l, c, err, errlen);
        }   /* other clauses belong to the address spaces, not to us */
        if (rc)
            return rc;
    }
    return 0;
}

int lab_load(const char *path, lab *l, char *err, int errlen)
{
    sx *top = sx_read_file(path, err, errlen);
    int rc;
    lab_defaults(l);
    if (!top)
        return -1;
    rc = read_lab(l, top, err, errlen);
    sx_free(top);
    return rc;
}
