/* Physics and sensing, through world.h directly (no sockets): the figures the
 * issue asks for, in a room small enough to reason about. */
#include <math.h>
#include <string.h>
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
    static const double targets[][3] = { { 300, 200, 0 }, { -1000, 200, 90 }, { 1500, -2000, -135 } };
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
          hypot(w->robots[r].at.x - (500 + 1000 * M_SQRT1_2), w->robots[r].at.y - (500 + 1000 * M_SQRT1_2)) < 20);
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
    world_free(w);
    lab_free(&l);
}

static void test_fiducials(void)
{
    lab l = room();
    lab_box ahead = { 1000, 1000, 400, 400, 30, 5 };   /* 45 degrees left, 1414 mm */
    lab_box behind = { -1500, 0, 400, 400, 0, 5 };
    lab_box walled = { 1000, -2000, 400, 400, 0, 5 };  /* behind the wall below */
    fiducial f[FIDUCIALS];
    int r, n, seen_ahead = 0, seen_other = 0, k;
    world *w;
    lab_add_box(&l, &ahead);
    lab_add_box(&l, &behind);
    lab_add_box(&l, &walled);
    lab_add_wall(&l, -3000, -1000, 3000, -1000, 50);
    r = add(&l, "a", 0, 0, 0);
    w = world_new(&l);
    world_step(w);
    n = robot_fiducials(w, r, f, FIDUCIALS);
    for (k = 0; k < n; k++) {
        if (f[k].id == 0)
            seen_ahead = fabs(f[k].range - 1414) < 5 && fabs(f[k].bearing - 45) < 1
                && fabs(f[k].orientation - 30) < 1;
        else
            seen_other = 1;
    }
    CHECK("the finder sees a box ahead, with its range, bearing and orientation", seen_ahead);
    CHECK("not one behind the robot, nor one behind a wall", !seen_other);
    robot_set_heading(w, r, 0);         /* odometry only: the true heading stays */
    w->robots[r].at.heading = 180;       /* turned round, by hand */
    n = robot_fiducials(w, r, f, FIDUCIALS);
    CHECK("turned round, it sees the one that was behind", n == 1 && f[0].id == 1
          && fabs(f[0].range - 1500) < 5 && fabs(f[0].bearing) < 1);
    w->robots[r].at.x = -1500 + 6000; /* far away: out of range */
    n = robot_fiducials(w, r, f, FIDUCIALS);
    CHECK("nothing beyond its range", n == 0);
    world_free(w);
    lab_free(&l);
}

static void test_stall(void)
{
    lab l = room();
    int r = add(&l, "a", 2500, 0, 0);
    world *w = world_new(&l);
    robot_translate(w, r, 2000);
    settle(w, r, 30);
    CHECK("driving into a wall stalls and ends the motion", idle(w, r) && w->robots[r].m.stalled);
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
            CHECK("same seed, same sonar readings", memcmp(first, w->robots[r].sonar, sizeof first) == 0);
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
            add(&l, "r", -2600 + 650 * (i % 9), -2600 + 1250 * (i / 9) + 120 * (i % 2), 37 * i);
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

int main(void)
{
    test_goto();
    test_odometry_frame();
    test_sonar_wall();
    test_push_box();
    test_fiducials();
    test_stall();
    test_battery();
    test_deterministic();
    test_against_box2d();
    return check_summary();
}
