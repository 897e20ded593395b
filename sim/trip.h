/* trip requests: one payload in, one reply payload out (docs/trip-protocol.md).
 * A session is what one connection holds: its robot and its device locks. */
#ifndef TRIP_H
#define TRIP_H
#include <stddef.h>
#include "world.h"

enum device { BASE, SONAR, IR, BUMPERS_DEV, SKIRT, BUTTONS_DEV, LIGHTS_DEV, SPEECH, BATTERY,
              FIDUCIAL, DEVICES };

enum { MAX_AWAITS = 8 };        /* base awaits one connection may have pending */

typedef struct {
    world *w;
    int robot;
    const char *lockdir;
    int lock[DEVICES];          /* flock'd file, or -1 */
    int stream;                 /* sonar stream on */
    int streamed;               /* sonar_seq last streamed */
    long awaits[MAX_AWAITS];    /* tags of base awaits not yet answered, 0 free */
} trip_session;

const char *trip_device_name(int device);
void trip_begin(trip_session *s, world *w, int robot, const char *lockdir);
/* Drop every lock the session holds. */
void trip_end(trip_session *s);
/* Answer one request; returns the reply's length (< cap). */
size_t trip_handle(trip_session *s, const char *req, size_t n, char *out, size_t cap);
/* A message due to the client that no request of this turn answered: the
 * deferred reply of a base await whose motion is over, or a tag 0 reading;
 * 0 when none.  Call it until it answers 0. */
size_t trip_event(trip_session *s, char *out, size_t cap);
#endif
