/* bench: real-time factors of the simulator, printed as
 *   bench: NAME VALUE x
 * sim-rtf-lab: the thesis's lab (three B14s, sonar at 10 Hz, the Tulane
 * room); sim-rtf-N: N B14s, each firing 16 sonars at 10 Hz, in a room with
 * boxes, wandering (drive, turn away from what the sonar sees) for 10 s and
 * resting 10 s in turn, as robots at work do; sim-rtf-N-moving: all of them
 * always on the move, so nothing can be reused; sim-rtf-N-box2d: the plain
 * Box2D loop of the same load -- three b2World ray casts per sonar, one
 * thread -- measured in the same run, as the reference.  sim-reuse-*: the
 * share of sonar readings whose geometry was reused because nothing near
 * the robot had moved. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include "world.h"

static double now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return ts.tv_sec + ts.tv_nsec * 1e-9;
}

static void walls(lab *l, double half)
{
    lab_add_wall(l, -half, -half, half, -half, 50);
    lab_add_wall(l, half, -half, half, half, 50);
    lab_add_wall(l, half, half, -half, half, 50);
    lab_add_wall(l, -half, half, -half, -half, 50);
}

static void add_robot(lab *l, int i, double x, double y, double h)
{
    lab_robot r;
    memset(&r, 0, sizeof r);
    snprintf(r.name, sizeof r.name, "r%d", i);
    r.aspace = i;
    r.x = x;
    r.y = y;
    r.heading = h;
    r.battery = 13.6;
    lab_add_robot(l, &r);
}

/* The thesis's room: 8 m square, a box, three robots. */
static void tulane(lab *l)
{
    lab_box b = { 1800, 1800, 600, 600, 0, 5 };
    lab_defaults(l);
    walls(l, 4000);
    lab_add_box(l, &b);
    add_robot(l, 0, 1200, -400, 180);
    add_robot(l, 1, -1800, -600, 90);
    add_robot(l, 2, 0, 2000, -90);
}

/* n robots on a 2 m lattice, a box in every tenth cell. */
static void crowd(lab *l, int n)
{
    int side = (int)ceil(sqrt(n * 1.1)), i, k = 0;
    double pitch = 2000, half = side * pitch / 2;
    lab_defaults(l);
    walls(l, half);
    for (i = 0; k < n; i++) {
        double x = -half + pitch * (i % side + 0.5), y = -half + pitch * (i / side + 0.5);
        if (i % 11 == 5) {
            lab_box b = { x, y, 600, 400, i * 7 % 90, 5 };
            lab_add_box(l, &b);
        } else {
            add_robot(l, k, x, y, (k * 37) % 360);
            k++;
        }
    }
}

/* Wander: drive unless the front sonars see something near, then turn. */
static void wander(world *w, int always)
{
    int i;
    for (i = 0; i < w->nrobots; i++) {
        robot *r = &w->robots[i];
        int resting = !always && ((int)(world_time(w) + i) / 10) % 2;
        double front = fmin(r->sonar[0], fmin(r->sonar[1], r->sonar[15]));
        r->sonar_on = 1;
        if (resting)
            robot_stop(w, i);
        else if (r->sonar_fired && front < 700)
            robot_velocity(w, i, 0, 60);
        else
            robot_velocity(w, i, 300, 0);
    }
}

static double reused;           /* share of the last run's readings */

static double rtf(lab *l, int plain, int always, double seconds)
{
    world *w = world_new(l);
    double start, wall;
    int steps = (int)(seconds * l->step_hz), k;
    w->plain = plain;
    start = now();
    for (k = 0; k < steps; k++) {
        wander(w, always);
        world_step(w);
    }
    wall = now() - start;
    reused = w->scans ? 100.0 * w->reused / w->scans : 0;
    world_free(w);
    return seconds / wall;
}

static void report(const char *name, double value, const char *unit)
{
    printf("bench: %s %.1f %s\n", name, value, unit);
    fflush(stdout);
}

int main(int argc, char **argv)
{
    static const int sizes[] = { 10, 100, 1000 };
    double seconds = argc > 1 ? atof(argv[1]) : 20;
    char name[64];
    lab l;
    size_t k;
    tulane(&l);
    report("sim-rtf-lab", rtf(&l, 0, 0, seconds * 10), "x");
    report("sim-reuse-lab", reused, "%");
    lab_free(&l);
    for (k = 0; k < sizeof sizes / sizeof sizes[0]; k++) {
        int n = sizes[k];
        crowd(&l, n);
        snprintf(name, sizeof name, "sim-rtf-%d", n);
        report(name, rtf(&l, 0, 0, seconds), "x");
        snprintf(name, sizeof name, "sim-reuse-%d", n);
        report(name, reused, "%");
        snprintf(name, sizeof name, "sim-rtf-%d-moving", n);
        report(name, rtf(&l, 0, 1, seconds), "x");
        snprintf(name, sizeof name, "sim-rtf-%d-box2d", n);
        report(name, rtf(&l, 1, 0, n >= 1000 ? seconds / 4 : seconds), "x");
        lab_free(&l);
    }
    return 0;
}
