/* A run as an animated SVG: walls, boxes and robots moving, each robot's
 * path, the sonar cones of its readings and what it said.  It plays in any
 * browser (SMIL animation), because people would rather watch a run than read
 * its numbers.  Kept in memory and written at the end, to a temporary name
 * renamed into place, so a trace file is never half written. */
#ifndef TRACE_H
#define TRACE_H
#include "world.h"

struct trace;

struct trace *trace_open(const char *path);
void trace_step(struct trace *t, const struct world *w);
void trace_sonar(struct trace *t, const struct world *w, int robot);
void trace_say(struct trace *t, const struct world *w, int robot, const char *text);
/* What a world calls to tell the trace t what happens (world.h). */
world_observer trace_observer(struct trace *t);
/* Write the file and free t; 0 or -1. */
int trace_close(struct trace *t, const struct world *w);
#endif
