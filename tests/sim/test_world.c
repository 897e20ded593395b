/* Physics and sensing, through world.h directly (no sockets): the figures the
 * issue asks for, in a room small enough to reason about. */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>
#include "check.h"
#include "../../sim/world.h"

static lab room(void)
{
    lab l;
    lab_defaults(&l);
    lab_add_wall(&l, -3000, -3000, 3000, -3000, 50);
    lab_add_wall(&l, 3000, -3000, 3000, 3000, 50);
    lab_add_wall(&l, 3000, 3000, -3000, 3000, 50);
    lab_add_wall(&l, -3000, 3000, -3000, -3000, 50);
    return l;
}

static int add(lab *l, const char *name, double x, double y, double h)
{
    lab_robot r;
    memset(&r, 0, sizeof r);
    strcpy(r.name, name);
    r.x = x; r.y = y; r.heading = h;
    r.battery = 13.0;
    return lab_add_robot(l, &r);
}

static void run(world *w, double seconds)
{
    int n = (int)(seconds / w->dt);
    while (n-- > 0)
        world_step(w);
}

static int idle(const world *w, int r)
{
    return w->robots[r].m.kind == IDLE;
}

/* Step until robot r's motion is over, at most `limit` seconds. */
static void settle(world *w, int r, double limit)
{
    double end = world_time(w) + limit;
    while (!idle(w, r) && world_time(w) < end)
        world_step(w);
}

static void test_goto(void)
{
    lab l = room();
    int r = add(&l, "a", -1000, -500, 30);
    world *w = world_new(&l);
    static const double targets[][3] = {
        { 300, 200, 0 }, { -1000, 200, 90 }, { 1500, -2000, -135 } };
    size_t k;
    for (k = 0; k < 3; k++) {
        pose p;
        robot_goto(w, r, targets[k][0], targets[k][1]);
        settle(w, r, 60);
        p = robot_reckon(w, r);
        robot_rotate(w, r, wrap180(targets[k][2] - p.heading));
        settle(w, r, 60);
        p = robot_reckon(w, r);
        CHECK("goto reaches x y within 2 cm",
              hypot(p.x - targets[k][0], p.y - targets[k][1]) < 20);
        CHECK("rotate reaches the heading within 2 degrees",
              fabs(wrap180(p.heading - targets[k][2])) < 2);
    }
    world_free(w);
    lab_free(&l);
}

static void test_odometry_frame(void)
{
    lab l = room();
    int r = add(&l, "a", 500, 500, 45);
    world *w = world_new(&l);
    pose p;
    robot_set_position(w, r, 0, 0);
    robot_set_heading(w, r, 0);
    p = robot_reckon(w, r);
    CHECK("set-position and set-heading make the origin here",
          fabs(p.x) < 1e-6 && fabs(p.y) < 1e-6 && fabs(p.heading) < 1e-6);
    robot_goto(w, r, 1000, 0);      /* along the old 45 degree heading */
    settle(w, r, 30);
    p = robot_reckon(w, r);
    CHECK("goto is in the odometry frame", hypot(p.x - 1000, p.y) < 20);
    CHECK("true pose moved along the old heading",
          hypot(w->robots[r].at.x - (500 + 1000 * M_SQRT1_2),
                w->robots[r].at.y - (500 + 1000 * M_SQRT1_2)) < 20);
    world_free(w);
    lab_free(&l);
}

static void test_sonar_wall(void)
{
    lab l;
    int r, k, ok = 1, n = 20;
    world *w;
    double sum = 0;
    lab_defaults(&l);
    lab_add_wall(&l, 2000, -3000, 2000, 3000, 50);
    r = add(&l, "a", 0, 0, 0);
    w = world_new(&l);
    for (k = 0; k < n; k++) {
        /* wall face at 1975, sonar on the skin at 180 */
        robot_sonar_fire(w, r);
        ok &= fabs(w->robots[r].sonar[0] - 1795) < 4 * l.b14.sonar_noise;
        sum += w->robots[r].sonar[0];
    }
    CHECK("sonar facing a wall reads its distance within the noise", ok);
    CHECK("sonar noise averages out", fabs(sum / n - 1795) < 2 * l.b14.sonar_noise);
    CHECK("sonar facing away sees nothing", w->robots[r].sonar[8] == l.b14.sonar_max);
    CHECK("a still robot reuses its geometry", w->reused >= n - 1);
    world_free(w);
    lab_free(&l);
}

static void test_push_box(void)
{
    lab l = room();
    lab_box b = { 800, 0, 600, 600, 0, 5 };
    int r, bumpers[BUMPERS], skirt[SKIRTS], front;
    double ir[IRS];
    world *w;
    pose before, after;
    lab_add_box(&l, &b);
    r = add(&l, "a", -500, 0, 0);
    w = world_new(&l);
    before = physics_box_pose(w->phys, 0);
    robot_velocity(w, r, 300, 0);
    run(w, 5);
    after = physics_box_pose(w->phys, 0);
    CHECK("driving into a box pushes it", after.x - before.x > 500);
    robot_contacts(w, r, bumpers, skirt);
    front = bumpers[5] || bumpers[6];
    CHECK("a front bumper reports the contact", front);
    CHECK("the front skirt segment is pressed", skirt[0] && !skirt[3]);
    robot_ir(w, r, ir);
    CHECK("ir sees the box at the front", ir[0] < 20 && ir[8] == l.b14.ir_range);
    {
        fiducial f[FIDUCIALS];
        int n = robot_fiducials(w, r, f, FIDUCIALS);
        CHECK("the fiducial finder sees the box it pushes, against its skin",
              n == 1 && fabs(f[0].range - 480) < 30 && fabs(f[0].bearing) < 10);
    }
    world_free(w);
    lab_free(&l);
}

/* A push at a corner turns the box about its far side, and a push at the
 * middle of a face does not: pushers steer a box by pushing unevenly. */
static double box_turned_by_push(double offset)
{
    lab l = room();
    lab_box b = { 800, 0, 600, 600, 0, 5 };
    int r;
    world *w;
    double turned;
    lab_add_box(&l, &b);
    r = add(&l, "a", 300, offset, 0);
    w = world_new(&l);
    robot_velocity(w, r, 200, 0);
    run(w, 3);
    turned = physics_box_pose(w->phys, 0).heading;
    world_free(w);
    lab_free(&l);
    return turned;
}

static void test_steer_box(void)
{
    CHECK("a push at the middle of a face drives the box straight",
          fabs(box_turned_by_push(0)) < 2);
    CHECK("a push at its left corner turns it clockwise", box_turned_by_push(200) < -5);
    CHECK("a push at its right corner turns it counter-clockwise",
          box_turned_by_push(-200) > 5);
}

/* The stall rule against a pushed box: a base is blocked only when it
 * makes under a fifth of its commanded progress, and a box that slides
 * lets it make all of it.  Two pushers side by side (MURDOCH's box move)
 * drive it at their speed and never stall; pushing a box into a wall
 * stalls, as pushing the wall itself does. */
static void test_push_box_stall(void)
{
    lab l = room();
    lab_box b = { 0, 0, 600, 600, 0, 5 };
    int r, stalled = 0, k;
    world *w;
    lab_add_box(&l, &b);
    add(&l, "a", -485, 190, 0);
    add(&l, "b", -485, -190, 0);
    w = world_new(&l);
    robot_velocity(w, 0, 200, 0);
    robot_velocity(w, 1, 200, 0);
    for (k = 0; k < 5 * 60; k++) {
        world_step(w);
        stalled |= w->robots[0].m.stalled || w->robots[1].m.stalled;
    }
    CHECK("two pushers drive a box at their speed",
          fabs(physics_box_pose(w->phys, 0).x - 1000) < 50);
    CHECK("and neither stalls", !stalled);
    world_free(w);
    lab_free(&l);

    l = room();
    b.x = 2500;
    lab_add_box(&l, &b);
    r = add(&l, "a", 1700, 0, 0);
    w = world_new(&l);
    robot_translate(w, r, 2000);
    settle(w, r, 30);
    CHECK("pushing a box into a wall stalls and ends the motion",
          idle(w, r) && w->robots[r].m.stalled);
    world_free(w);
    lab_free(&l);
}

/* ---- the fiducial finder ----------------------------------------------
 * Each case is a room of its own, 16 m across so that its walls are out of
 * the way, with a robot at the origin facing `heading` and the boxes given. */

static lab open_room(void)
{
    lab l;
    lab_defaults(&l);
    lab_add_wall(&l, -8000, -8000, 8000, -8000, 50);
    lab_add_wall(&l, 8000, -8000, 8000, 8000, 50);
    lab_add_wall(&l, 8000, 8000, -8000, 8000, 50);
    lab_add_wall(&l, -8000, 8000, -8000, -8000, 50);
    return l;
}

static void put_box(lab *l, double x, double y, double w, double d, double heading)
{
    lab_box b = { x, y, w, d, heading, 5 };
    lab_add_box(l, &b);
}

/* What the robot at the origin, facing `heading`, sees of l (freed). */
static int look(lab *l, double heading, fiducial *f, int max)
{
    int r = add(l, "a", 0, 0, heading), n;
    world *w = world_new(l);
    world_step(w);
    n = robot_fiducials(w, r, f, max);
    world_free(w);
    lab_free(l);
    return n;
}

static int find(const fiducial *f, int n, int id)
{
    int k;
    for (k = 0; k < n; k++)
        if (f[k].id == id)
            return k;
    return -1;
}

static void test_fiducials(void)
{
    fiducial f[FIDUCIALS];
    lab l;
    int n, k;

    l = open_room();
    put_box(&l, 1000, 1000, 400, 400, 30);      /* 1414 mm at 45 degrees left */
    n = look(&l, 20, f, FIDUCIALS);
    CHECK("a box in view is seen, by its index", n == 1 && f[0].id == 0);
    CHECK("its range, centre to centre, in mm", n == 1 && fabs(f[0].range - 1414.2) < 2);
    CHECK("its bearing from the robot's heading",
          n == 1 && fabs(f[0].bearing - 25) < 0.5);
    CHECK("its heading relative to the robot's",
          n == 1 && fabs(f[0].orientation - 10) < 0.5);

    l = open_room();
    put_box(&l, -1500, 0, 400, 400, 0);
    CHECK("a box behind the robot is not seen", look(&l, 0, f, FIDUCIALS) == 0);
    l = open_room();
    put_box(&l, -1500, 0, 400, 400, 0);
    n = look(&l, 180, f, FIDUCIALS);
    CHECK("turned round, the robot sees it dead ahead",
          n == 1 && fabs(f[0].range - 1500) < 2
          && fabs(f[0].bearing) < 0.5 && fabs(fabs(f[0].orientation) - 180) < 0.5);

    l = open_room();
    put_box(&l, -347.3, 1969.6, 400, 400, 0);   /* 2000 mm, 100 degrees left */
    put_box(&l, 347.3, -1969.6, 400, 400, 0);   /* 2000 mm, 80 degrees right */
    n = look(&l, 0, f, FIDUCIALS);
    CHECK("the field of view is 180 degrees: 80 degrees off is in it, 100 is not",
          n == 1 && f[0].id == 1 && fabs(f[0].bearing + 80) < 0.5);
    l = open_room();
    put_box(&l, -347.3, 1969.6, 400, 400, 0);
    l.b14.fiducial_fov = 240;
    CHECK("a wider field of view (b14 fiducial-fov) takes it in",
          look(&l, 0, f, FIDUCIALS) == 1);

    l = open_room();
    put_box(&l, 4900, 0, 400, 400, 0);
    put_box(&l, 0, 5100, 400, 400, 0);
    n = look(&l, 45, f, FIDUCIALS);
    CHECK("the range is 5 m: a box at 4.9 m in plain sight is seen, one at 5.1 m is not",
          n == 1 && f[0].id == 0 && fabs(f[0].range - 4900) < 2);
    l = open_room();
    put_box(&l, 4900, 0, 400, 400, 0);
    l.b14.fiducial_range = 4000;
    CHECK("a shorter range (b14 fiducial-range) leaves it out",
          look(&l, 0, f, FIDUCIALS) == 0);

    l = open_room();
    put_box(&l, 3000, 0, 600, 600, 0);
    lab_add_wall(&l, 2000, -1500, 2000, 1500, 50);
    CHECK("a box behind a wall is not seen", look(&l, 0, f, FIDUCIALS) == 0);
    l = open_room();
    put_box(&l, 3000, 0, 600, 600, 0);
    lab_add_wall(&l, 2000, -100, 2000, 100, 50);    /* a post on the line of sight */
    n = look(&l, 0, f, FIDUCIALS);
    CHECK("a box whose centre a post hides is seen by its corners",
          n == 1 && fabs(f[0].range - 3000) < 2 && fabs(f[0].bearing) < 0.5);

    l = open_room();
    put_box(&l, 1500, 0, 400, 400, 0);
    put_box(&l, 3000, 0, 400, 400, 0);              /* wholly behind the first */
    n = look(&l, 0, f, FIDUCIALS);
    CHECK("a box hidden by another box is not seen; the nearer one is",
          n == 1 && f[0].id == 0);
    l = open_room();
    put_box(&l, 3000, 0, 400, 400, 0);
    add(&l, "b", 1500, 0, 0);                       /* another robot in the way */
    n = look(&l, 0, f, FIDUCIALS);
    CHECK("nor one hidden by another robot", n == 0);

    l = open_room();
    put_box(&l, 3000, 1500, 400, 400, 0);
    put_box(&l, 1000, -500, 400, 400, 0);
    put_box(&l, 2000, 0, 400, 400, 0);
    n = look(&l, 0, f, FIDUCIALS);
    CHECK("several boxes are told nearest first",
          n == 3 && f[0].id == 1 && f[1].id == 2 && f[2].id == 0);
    l = open_room();
    put_box(&l, 3000, 1500, 400, 400, 0);
    put_box(&l, 1000, -500, 400, 400, 0);
    put_box(&l, 2000, 0, 400, 400, 0);
    n = look(&l, 0, f, 2);
    CHECK("at most max of them, the nearest", n == 2 && f[0].id == 1 && f[1].id == 2);

    l = open_room();
    for (k = 0; k < 40; k++)                        /* a row of 40 small boxes */
        put_box(&l, 1000 + 90 * (k % 10), -1500 + 1000 * (k / 10), 50, 50, 0);
    n = look(&l, 0, f, FIDUCIALS);
    CHECK("a crowd is cut at FIDUCIALS", n == FIDUCIALS && find(f, n, 0) >= 0);
}

static void test_stall(void)
{
    lab l = room();
    int r = add(&l, "a", 2500, 0, 0);
    world *w = world_new(&l);
    robot_translate(w, r, 2000);
    settle(w, r, 30);
    CHECK("driving into a wall stalls and ends the motion",
          idle(w, r) && w->robots[r].m.stalled);
    world_free(w);
    lab_free(&l);
}

static void test_battery(void)
{
    lab l = room();
    int r = add(&l, "a", 0, 0, 0);
    world *w = world_new(&l);
    double v0 = w->robots[r].battery, v1;
    robot_velocity(w, r, 0, 30);
    run(w, 10);
    v1 = w->robots[r].battery;
    CHECK("moving drains the battery", v1 < v0 - 0.01);
    w->robots[r].tethered = 1;
    robot_stop(w, r);
    run(w, 10);
    CHECK("the tether recharges it", w->robots[r].battery > v1 + 0.05);
    world_free(w);
    lab_free(&l);
}

/* Same seed, same commands at the same steps: the same run. */
static void test_deterministic(void)
{
    double first[SONARS];
    pose at[2];
    int k;
    for (k = 0; k < 2; k++) {
        lab l = room();
        lab_box b = { 1000, 500, 400, 400, 10, 5 };
        int r;
        world *w;
        lab_add_box(&l, &b);
        r = add(&l, "a", 0, 0, 0);
        add(&l, "b", -1000, 0, 0);
        w = world_new(&l);
        w->robots[r].sonar_on = 1;
        robot_velocity(w, r, 250, 10);
        robot_goto(w, 1, 1000, -1000);
        run(w, 6);
        if (k == 0)
            memcpy(first, w->robots[r].sonar, sizeof first);
        else
            CHECK("same seed, same sonar readings",
                  memcmp(first, w->robots[r].sonar, sizeof first) == 0);
        at[k] = w->robots[r].at;
        world_free(w);
        lab_free(&l);
    }
    CHECK("same seed, same path", memcmp(&at[0], &at[1], sizeof at[0]) == 0);
}

/* The grid's ray casting (threaded, from a snapshot, published a round
 * late) against Box2D's own ray cast in the same room: the same ranges. */
static void test_against_box2d(void)
{
    double fast[40][SONARS];
    int pass, i, k, agree = 1, rounds = 0;
    for (pass = 0; pass < 2; pass++) {
        lab l = room();
        world *w;
        for (i = 0; i < 6; i++) {
            lab_box b = { -2400 + 950 * i, 900 * (i % 3) - 900, 500, 300, 17 * i, 5 };
            lab_add_box(&l, &b);
        }
        for (i = 0; i < 40; i++)
            add(&l, "r", -2600 + 650 * (i % 9), -2600 + 1250 * (i / 9) + 120 * (i % 2),
                37 * i);
        l.b14.sonar_noise = 0;
        w = world_new(&l);
        w->plain = pass;
        for (i = 0; i < 40; i++)
            w->robots[i].sonar_on = 1;
        world_step(w);          /* step 1: no round */
        while (w->step % 6 != 0)
            world_step(w);      /* the round fires at step 6 */
        world_sync(w);
        rounds += w->scans == 40;
        for (i = 0; i < 40; i++)
            for (k = 0; k < SONARS; k++) {
                if (pass == 0)
                    fast[i][k] = w->robots[i].sonar[k];
                else
                    agree &= fabs(fast[i][k] - w->robots[i].sonar[k]) < 1;
            }
        world_free(w);
        lab_free(&l);
    }
    CHECK("a round of 40 readings was taken", rounds == 2);
    CHECK("the grid's ranges match Box2D's ray casts within 1 mm", agree);
}

/* The simulator reads its lab file itself: a size or a mass of 0 or less
 * is refused there too, not handed to Box2D. */
static int loads(const char *text)
{
    char path[] = "/tmp/murdoch-test-world.XXXXXX", err[256];
    int fd = mkstemp(path), rc;
    FILE *f = fd >= 0 ? fdopen(fd, "w") : NULL;
    lab l;
    if (!f)
        return -2;
    fputs(text, f);
    fclose(f);
    rc = lab_load(path, &l, err, sizeof err);
    unlink(path);
    if (rc == 0)
        lab_free(&l);
    return rc;
}

static void test_sizes_read(void)
{
    CHECK("a box as the lab file gives it",
          loads("(lab x (world (box 0 0 600 400 30 2)))") == 0);
    CHECK("a box of negative depth is refused",
          loads("(lab x (world (box 0 0 600 -400 30)))") != 0);
    CHECK("a box of no mass is refused",
          loads("(lab x (world (box 0 0 600 400 30 0)))") != 0);
    CHECK("a wall of no thickness is refused",
          loads("(lab x (world (wall 0 0 1000 0 0)))") != 0);
}

int main(void)
{
    test_sizes_read();
    test_goto();
    test_odometry_frame();
    test_sonar_wall();
    test_push_box();
    test_steer_box();
    test_push_box_stall();
    test_fiducials();
    test_stall();
    test_battery();
    test_deterministic();
    test_against_box2d();
    return check_summary();
}
