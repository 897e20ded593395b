/* The simulated lab: B14s, boxes and walls, stepped at a fixed rate.  One
 * step is a pipeline: controllers set wheel velocities, Box2D moves the
 * bodies, the sensing grid is refiled from the new poses, batteries and
 * stalls are updated, and the sonars that are due fire (in parallel when
 * there are many).  Everything a robot reports is computed here; trip.c only
 * turns requests into calls of these procedures. */
#ifndef WORLD_H
#define WORLD_H
#include <stdint.h>
#include "lab.h"
#include "physics.h"
#include "sense.h"

enum { SONARS = 16, IRS = 16, BUMPERS = 12, SKIRTS = 6, BUTTONS = 4, LIGHTS = 4 };

enum motion_kind { IDLE, VELOCITY, TRANSLATE, ROTATE, GOTO };

typedef struct {
    enum motion_kind kind;
    double tv, rv;              /* VELOCITY: mm/s, deg/s */
    double left;                /* TRANSLATE: mm; ROTATE: deg */
    double gx, gy;              /* GOTO target, true frame */
    int turning;                /* GOTO: still turning to face the target */
    double stuck;               /* seconds the wheels have been blocked */
    int stalled;
} motion;

typedef struct {
    char name[64];
    int body, circle;
    pose at, before;            /* true pose now and one step ago */
    double odx, ody, odth;      /* odometry = rotate(odth) true + (odx, ody) */
    motion m;
    double v, w;                /* what the wheels were told this step */
    double battery;
    int tethered;
    int sonar_on, sonar_fired;
    double sonar[SONARS];       /* last reading, with noise */
    double sonar_geo[SONARS];   /* its noiseless geometry, for reuse */
    pose sonar_at;
    int sonar_step;
    double sonar_reach;
    int sonar_seq;              /* readings so far */
    int buttons[BUTTONS], lights[LIGHTS];
    uint64_t rng;
} robot;

struct trace;

typedef struct world {
    lab *lab;
    physics *phys;
    sense *sense;
    robot *robots;
    int nrobots;
    int step;
    double dt;
    int threads;                /* sonar workers, counting the caller */
    int plain;                  /* sense through Box2D's ray cast, one thread,
                                   no reuse: the bench's reference */
    struct trace *trace;        /* NULL: no trace */
    double *fan;                /* sonar rays then ir rays: cos, sin of the
                                   offset from the heading, in pairs */
    int *fan_sonar;             /* the sonar each sonar ray belongs to */
    sense_scratch scratch[2];   /* one per sonar worker */
    long scans, reused;         /* sonar statistics */
} world;

world *world_new(lab *l);
void world_free(world *w);
void world_step(world *w);
double world_time(const world *w);     /* simulated seconds */

/* Motions (odometry frame, mm and degrees) */
void robot_velocity(world *w, int r, double tv, double rv);
void robot_translate(world *w, int r, double d);
void robot_rotate(world *w, int r, double a);
void robot_goto(world *w, int r, double x, double y);
void robot_stop(world *w, int r);
pose robot_reckon(const world *w, int r);
void robot_set_position(world *w, int r, double x, double y);
void robot_set_heading(world *w, int r, double h);

/* Sensors */
void robot_sonar_fire(world *w, int r);
void robot_ir(world *w, int r, double out[IRS]);
void robot_contacts(const world *w, int r, int bumpers[BUMPERS], int skirt[SKIRTS]);
void robot_say(world *w, int r, const char *text, size_t n);

double wrap180(double a);
#endif
