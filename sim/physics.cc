// Box2D behind the C interface of physics.h.
#include <box2d/box2d.h>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <new>
#include <vector>
#include "physics.h"

static const double MM = 0.001;              // metres per millimetre
static const double DEG = M_PI / 180.0;
static const double G = 9.81;

struct physics {
    b2World world{b2Vec2(0, 0)};
    b2Body *ground;
    std::vector<b2Body *> robots, boxes;
};

static pose pose_of(const b2Body *b)
{
    b2Vec2 at = b->GetPosition();
    return pose{at.x / MM, at.y / MM, b->GetAngle() / DEG};
}

// Our own allocations are checked as sim/alloc.h checks C's: no C++
// exception may unwind through the C callers.  (Box2D's own allocations,
// inside the library, are Box2D's.)
[[noreturn]] static void out_of_memory()
{
    std::fputs("b14: ERROR: out of memory\n", stderr);
    std::exit(1);
}

static int keep(std::vector<b2Body *> &v, b2Body *b)
{
    try {
        v.push_back(b);
    } catch (const std::bad_alloc &) {
        out_of_memory();
    }
    return (int)v.size() - 1;
}

physics *physics_new(void)
{
    physics *p = new (std::nothrow) physics;
    if (!p)
        out_of_memory();
    b2BodyDef def;
    p->ground = p->world.CreateBody(&def);
    return p;
}

void physics_free(physics *p)
{
    delete p;
}

void physics_add_wall(physics *p, double x1, double y1, double x2, double y2, double thick)
{
    b2BodyDef def;
    double dx = x2 - x1, dy = y2 - y1;
    def.position.Set((x1 + x2) / 2 * MM, (y1 + y2) / 2 * MM);
    def.angle = atan2(dy, dx);
    b2Body *wall = p->world.CreateBody(&def);
    b2PolygonShape shape;
    // walls overlap at the corners by half their thickness, as drawn
    shape.SetAsBox((hypot(dx, dy) + thick) / 2 * MM, thick / 2 * MM);
    wall->CreateFixture(&shape, 0);
}

int physics_add_box(physics *p, pose at, double w, double d, double mass, double mu)
{
    b2BodyDef def;
    def.type = b2_dynamicBody;
    def.position.Set(at.x * MM, at.y * MM);
    def.angle = at.heading * DEG;
    b2Body *box = p->world.CreateBody(&def);
    b2PolygonShape shape;
    shape.SetAsBox(w / 2 * MM, d / 2 * MM);
    b2FixtureDef fix;
    fix.shape = &shape;
    fix.density = mass / (w * d * MM * MM);
    fix.friction = 0.3f;
    box->CreateFixture(&fix);
    // Friction with the floor, seen from above: the box's weight rests on
    // a 3 x 3 grid of points, each holding its share of mu m g against
    // sliding.  One joint at the centre, with a torque of its own, would
    // let a push off the centre slide the box without turning it, so that
    // pushers could never steer it; spread out, a push at a corner turns
    // the box about the far side, as on a real floor.
    for (int i = -1; i <= 1; i++)
        for (int j = -1; j <= 1; j++) {
            b2FrictionJointDef joint;
            joint.Initialize(p->ground, box, box->GetWorldPoint(b2Vec2(i * w / 3 * MM, j * d / 3 * MM)));
            joint.maxForce = mu * mass * G / 9;
            joint.maxTorque = 0;
            p->world.CreateJoint(&joint);
        }
    return keep(p->boxes, box);
}

int physics_add_robot(physics *p, pose at, double radius, double mass)
{
    b2BodyDef def;
    def.type = b2_dynamicBody;
    def.position.Set(at.x * MM, at.y * MM);
    def.angle = at.heading * DEG;
    def.bullet = false;
    b2Body *robot = p->world.CreateBody(&def);
    b2CircleShape shape;
    shape.m_radius = radius * MM;
    b2FixtureDef fix;
    fix.shape = &shape;
    fix.density = mass / (M_PI * shape.m_radius * shape.m_radius);
    fix.friction = 0.3f;
    robot->CreateFixture(&fix);
    return keep(p->robots, robot);
}

void physics_drive(physics *p, int robot, double v, double turn)
{
    b2Body *b = p->robots[robot];
    double h = b->GetAngle();
    // the wheels hold the body to the commanded motion each step; contacts
    // within the step still push it back, which is how a robot stalls
    b->SetLinearVelocity(b2Vec2(v * MM * cos(h), v * MM * sin(h)));
    b->SetAngularVelocity(turn * DEG);
}

void physics_step(physics *p, double dt)
{
    p->world.Step(dt, 8, 3);
}

pose physics_robot_pose(const physics *p, int robot)
{
    return pose_of(p->robots[robot]);
}

pose physics_box_pose(const physics *p, int box)
{
    return pose_of(p->boxes[box]);
}

int physics_robot_touches(const physics *p, int robot, double *dirs, int max)
{
    const b2Body *b = p->robots[robot];
    b2Vec2 c = b->GetPosition();
    int n = 0;
    for (const b2ContactEdge *e = b->GetContactList(); e && n < max; e = e->next) {
        b2Contact *k = e->contact;
        if (!k->IsTouching())
            continue;
        b2WorldManifold m;
        k->GetWorldManifold(&m);
        for (int i = 0; i < k->GetManifold()->pointCount && n < max; i++)
            dirs[n++] = atan2(m.points[i].y - c.y, m.points[i].x - c.x) / DEG;
    }
    return n;
}

namespace {
struct nearest : b2RayCastCallback {
    const b2Body *self;
    float fraction = 1;
    float ReportFixture(b2Fixture *f, const b2Vec2 &, const b2Vec2 &, float frac) override
    {
        if (f->GetBody() == self)
            return -1;
        fraction = frac;
        return frac;
    }
};
}

double physics_ray(const physics *p, int robot, double x, double y, double dx, double dy, double range)
{
    nearest cb;
    cb.self = p->robots[robot];
    b2Vec2 from(x * MM, y * MM);
    b2Vec2 to((x + range * dx) * MM, (y + range * dy) * MM);
    p->world.RayCast(&cb, from, to);
    return cb.fraction * range;
}
