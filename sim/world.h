/* The simulated lab: B14s, boxes and walls, stepped at a fixed rate.  One
 * step is a pipeline: controllers set wheel velocities, Box2D moves the
 * bodies, the sensing grid is refiled from the new poses, batteries and
 * stalls are updated, and the sonars that are due fire.  A round of many
 * readings is taken by a helper thread from a snapshot of the grid while
 * the following steps go on, and published at the next round (the caller
 * lends a hand then if the helper is behind): readings in a crowd arrive
 * one round late, as a real ring's do.  A few readings are taken at once.
 * Everything a robot reports is computed here; trip.c only turns requests
 * into calls of these procedures. */
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

/* What a reading leaves behind for the next one of the same robot. */
typedef struct {
    pose at;                    /* where the robot was */
    int step;                   /* when; -1: never */
    double geo[SONARS];         /* noiseless ranges, reused if nothing moved */
    double reach;               /* how far that geometry looked */
    uint64_t rng;               /* the robot's noise stream */
} sonar_state;

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
    int sonar_seq;              /* readings so far */
    sonar_state ss;
    int buttons[BUTTONS], lights[LIGHTS];
} robot;

struct round;
struct world;

/* Whoever watches the world run (the trace, sim/trace.c): handed to the
 * world by whoever made both, so that the world knows no watcher's
 * insides.  Each procedure may be NULL. */
typedef struct {
    void *data;
    void (*step)(void *data, const struct world *w);            /* a step ended */
    void (*sonar)(void *data, const struct world *w, int robot); /* a reading */
    void (*say)(void *data, const struct world *w, int robot, const char *text);
} world_observer;

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
    world_observer observer;    /* all NULL: nobody watches */
    double *fan;                /* sonar rays then ir rays: cos, sin of the
                                   offset from the heading, in pairs */
    int *fan_sonar;             /* the sonar each sonar ray belongs to */
    sense_scratch scratch[2];   /* [0] the caller's, [1] the helper's */
    struct round *round;        /* the round of readings under way */
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
void robot_sonar_on(world *w, int r, int on);   /* fire at the sonar rate, or stop */
void robot_sonar_fire(world *w, int r);
/* Finish and publish the round of readings under way, if any. */
void world_sync(world *w);
void robot_ir(world *w, int r, double out[IRS]);
void robot_contacts(const world *w, int r, int bumpers[BUMPERS], int skirt[SKIRTS]);
void robot_say(world *w, int r, const char *text, size_t n);

/* What a finger on the robot, or its owner, does */
void robot_button(world *w, int r, int button, int pressed);
void robot_take_buttons(world *w, int r, int out[BUTTONS]);  /* read, then clear */
void robot_light(world *w, int r, int light, int on);
void robot_tether(world *w, int r, int on);

/* A fiducial finder, as Stage's: a marker on every box.  A box is seen
 * when its centre lies within the b14's fiducial-range (mm) and within
 * its fiducial-fov (degrees, centred on the heading), and the line from
 * the robot's centre to the box's centre, or to one of its corners, meets
 * this box before anything else (a wall, a robot, another box).  It is
 * told as its index among the lab's boxes, its range (mm, centre to
 * centre), its bearing (degrees from the heading, counter-clockwise) and
 * its heading less the robot's (degrees): what a fiducial on the box
 * tells, not where the box is in the room.  Fills out with the nearest
 * max boxes seen, nearest first; answers how many.  FIDUCIALS is as many
 * as a trip reply holds. */
enum { FIDUCIALS = 32 };
typedef struct { int id; double range, bearing, orientation; } fiducial;
int robot_fiducials(world *w, int r, fiducial *out, int max);

double wrap180(double a);
#endif
