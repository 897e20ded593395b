/* The lab file as the simulator needs it: robots, room, settings.  Defaults
 * are those of docs/trip-protocol.md. */
#ifndef LAB_H
#define LAB_H

typedef struct { double x1, y1, x2, y2, thick; } lab_wall;
typedef struct { double x, y, w, d, heading, mass; } lab_box;

typedef struct {
    char name[64];
    int aspace;                 /* index of its (aspace ...) clause */
    int trip_port;              /* 0: port-base + 100 + aspace */
    double x, y, heading;
    int tethered;
    double battery;
} lab_robot;

typedef struct {
    double radius, mass, max_speed, max_turn, speed, turn;
    double sonar_min, sonar_max, sonar_cone, sonar_noise, sonar_hz;
    int sonar_rays;
    double ir_range;
    double fiducial_range, fiducial_fov;    /* mm; degrees, centred on the heading */
    double drain, idle, charge, v_low, v_high;
    int max_frame;
} b14_params;

typedef struct {
    int port_base;
    char interface[64];
    int step_hz;
    unsigned long seed;
    double speed;               /* simulated s per wall s; 0: as fast as possible */
    double friction;
    double stall_timeout;       /* wall seconds a client may sit on half a frame */
    b14_params b14;
    lab_robot *robots;
    int nrobots;
    lab_wall *walls;
    int nwalls;
    lab_box *boxes;
    int nboxes;
} lab;

void lab_defaults(lab *l);
/* Fill l from the file; 0, or -1 with a message in err. */
int lab_load(const char *path, lab *l, char *err, int errlen);
int lab_add_robot(lab *l, const lab_robot *r);
void lab_add_wall(lab *l, double x1, double y1, double x2, double y2, double thick);
void lab_add_box(lab *l, const lab_box *b);
int lab_trip_port(const lab *l, const lab_robot *r);
void lab_free(lab *l);
#endif
