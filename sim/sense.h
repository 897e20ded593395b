/* Range sensing without the physics engine: the room as segments (walls and
 * box edges) and circles (robots) in a uniform grid.  A robot's rays all
 * start at its centre, so they are cast together: the cells around it are
 * visited ring by ring, nearest first; each shape found is met once, and only
 * the rays within the angle it subtends are intersected with it; the search
 * stops as soon as every ray has hit something nearer than the next ring.
 * Walls are filed once;
 * moving shapes are refiled every step, and each cell remembers the last step
 * something moved in it, so a robot whose surroundings stood still can reuse
 * its last geometry (see world.c). */
#ifndef SENSE_H
#define SENSE_H
#include "physics.h"

typedef struct sense sense;

/* fmin and fmax are calls, for their NaN rules; these are an instruction. */
static inline double lesser(double a, double b) { return a < b ? a : b; }
static inline double greater(double a, double b) { return a > b ? a : b; }

/* The grid covers [x0, x1] x [y0, y1] in cells of `cell` mm; shapes outside
 * it are filed in the border cells. */
sense *sense_new(double x0, double y0, double x1, double y1, double cell);
void sense_free(sense *s);
void sense_add_wall(sense *s, double x1, double y1, double x2, double y2, double thick);
int sense_add_box(sense *s, double w, double d);
int sense_add_circle(sense *s, double radius);
void sense_place_box(sense *s, int box, pose at);
void sense_place_circle(sense *s, int circle, double x, double y);
/* Copy the grid and every shape into `into` (made when NULL), for a
 * thread that casts while the original moves on; returns the copy. */
sense *sense_snapshot(sense *into, const sense *from);
/* Refile what moved; `step` stamps the cells it left and entered. */
void sense_refile(sense *s, int step);
/* Per-thread working memory of sense_fan: which shapes this cast has met. */
typedef struct {
    unsigned *met;
    int cap;
    unsigned cast;
    double angle[2 * 256];      /* the rays' pseudo-angles, ascending, twice */
    int ray[2 * 256];           /* which ray each is */
    int n;
} sense_scratch;

void sense_scratch_free(sense_scratch *sc);
/* For each of the n rays from (x, y) along unit vectors (dx[k], dy[k]), the
 * distance to the nearest shape other than circle `self`, or range.  The
 * rays must go round counter-clockwise (from any start); n <= SENSE_MAX_RAYS. */
enum { SENSE_MAX_RAYS = 256 };
void sense_fan(const sense *s, sense_scratch *sc, int self, double x, double y,
               const double *dx, const double *dy, int n, double range, double *out);
/* True when nothing moved within `reach` of (x, y) after step `since`. */
int sense_still(const sense *s, double x, double y, double reach, int since);
#endif
