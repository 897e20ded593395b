/* The rigid-body world, reached from C.  Box2D 2.4 is C++; physics.cc is the
 * only C++ in the simulator.  Lengths here are millimetres and angles
 * degrees, as everywhere in Murdoch; the glue converts to Box2D's metres and
 * radians, where its solver is tuned. */
#ifndef PHYSICS_H
#define PHYSICS_H
#ifdef __cplusplus
extern "C" {
#endif

typedef struct physics physics;

typedef struct { double x, y, heading; } pose;

physics *physics_new(void);
void physics_free(physics *p);
void physics_add_wall(physics *p, double x1, double y1, double x2, double y2, double thick);
/* Boxes are dragged over the floor by a friction joint: mu * m * g. */
int physics_add_box(physics *p, pose at, double w, double d, double mass, double mu);
int physics_add_robot(physics *p, pose at, double radius, double mass);
/* Synchro drive: v (mm/s) along the heading, turn (deg/s) about the centre. */
void physics_drive(physics *p, int robot, double v, double turn);
void physics_step(physics *p, double dt);
pose physics_robot_pose(const physics *p, int robot);
pose physics_box_pose(const physics *p, int box);
/* Directions (world degrees) from a robot's centre to the points where it
 * touches something; returns how many, at most max. */
int physics_robot_touches(const physics *p, int robot, double *dirs, int max);
/* The plain loop the bench compares against: Box2D's own ray cast, nearest
 * hit from (x, y) along the unit vector (dx, dy) within range, mm; range
 * when nothing.  Ignores the robot's own body. */
double physics_ray(const physics *p, int robot, double x, double y, double dx, double dy, double range);

#ifdef __cplusplus
}
#endif
#endif
