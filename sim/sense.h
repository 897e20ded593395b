/* Range sensing without the physics engine: the room as segments (walls and
 * box edges) and circles (robots) in a uniform grid, so that a ray visits only
 * the few cells it crosses and the few shapes in them.  Walls are filed once;
 * moving shapes are refiled every step, and each cell remembers the last step
 * something moved in it, so a robot whose surroundings stood still can reuse
 * its last geometry (see world.c). */
#ifndef SENSE_H
#define SENSE_H
#include "physics.h"

typedef struct sense sense;

/* The grid covers [x0, x1] x [y0, y1] in cells of `cell` mm; shapes outside
 * it are filed in the border cells. */
sense *sense_new(double x0, double y0, double x1, double y1, double cell);
void sense_free(sense *s);
void sense_add_wall(sense *s, double x1, double y1, double x2, double y2, double thick);
int sense_add_box(sense *s, double w, double d);
int sense_add_circle(sense *s, double radius);
void sense_place_box(sense *s, int box, pose at);
void sense_place_circle(sense *s, int circle, double x, double y);
/* Refile what moved; `step` stamps the cells it left and entered. */
void sense_refile(sense *s, int step);
/* Distance along the ray from (x, y) to the nearest shape, not counting
 * circle `self`; range when nothing is nearer. */
double sense_ray(const sense *s, int self, double x, double y, double dir_deg, double range);
/* True when nothing moved within `reach` of (x, y) after step `since`. */
int sense_still(const sense *s, double x, double y, double reach, int since);
#endif
