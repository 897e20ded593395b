/* trip requests: one payload in, one reply payload out (docs/trip-protocol.md).
 * A session is what one connection holds: its robot and its device locks. */
#ifndef TRIP_H
#define TRIP_H
#include <stddef.h>
#include "world.h"

enum device { BASE, SONAR, IR, BUMPERS_DEV, SKIRT, BUTTONS_DEV, LIGHTS_DEV, SPEECH, BATTERY,
              FIDUCIAL, DEVICES };

typedef struct {
    world *w;
    int robot;
    const char *lockdir;
    int lock[DEVICES];          /* flock'd file, or -1 */
    int stream;                 /* sonar stream on */
    int streamed;               /* sonar_seq last streamed */
} trip_session;

const char *trip_device_name(int device);
void trip_begin(trip_session *s, world *w, int robot, const char *lockdir);
/* Drop every lock the session holds. */
void trip_end(trip_session *s);
/* Answer one request; returns the reply's length (< cap). */
size_t trip_handle(trip_session *s, const char *req, size_t n, char *out, size_t cap);
/* An asynchronous message due to the client (tag 0), or 0 when none. */
size_t trip_event(trip_session *s, char *out, size_t cap);
#endif
