#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "sense.h"

typedef struct { double x1, y1, x2, y2; } segment;
typedef struct { double x, y, r; int moved; } circle;
typedef struct { double w, d; pose at; int moved; } box;

/* A grid of cells, each a run of shape ids in one array (built by counting,
 * so refiling allocates nothing).  id >= 0: segment; id < 0: circle ~id. */
typedef struct {
    int *start;                 /* cells + 1 offsets */
    int *ids;
    int nids, capids;
} filing;

struct sense {
    double x0, y0, cell;
    int nx, ny;
    segment *segs;              /* walls first, then 4 per box */
    int nsegs, nwall_segs;
    circle *circles;
    int ncircles;
    box *boxes;
    int nboxes;
    filing walls, moving;
    int *changed;               /* per cell: last step something moved there */
    int *count;                 /* scratch for filing */
};

static void *xrealloc(void *p, size_t n)
{
    p = realloc(p, n ? n : 1);
    if (!p) {
        perror("b14");
        exit(1);
    }
    return p;
}

sense *sense_new(double x0, double y0, double x1, double y1, double cell)
{
    sense *s = calloc(1, sizeof *s);
    int cells;
    s->x0 = x0;
    s->y0 = y0;
    s->cell = cell;
    s->nx = (int)ceil((x1 - x0) / cell) + 1;
    s->ny = (int)ceil((y1 - y0) / cell) + 1;
    cells = s->nx * s->ny;
    s->walls.start = calloc(cells + 1, sizeof(int));
    s->moving.start = calloc(cells + 1, sizeof(int));
    s->changed = calloc(cells, sizeof(int));
    s->count = calloc(cells + 1, sizeof(int));
    memset(s->changed, 0xff, cells * sizeof(int));   /* -1: never */
    return s;
}

void sense_free(sense *s)
{
    free(s->segs);
    free(s->circles);
    free(s->boxes);
    free(s->walls.start);
    free(s->walls.ids);
    free(s->moving.start);
    free(s->moving.ids);
    free(s->changed);
    free(s->count);
    free(s);
}

static int clampi(int v, int lo, int hi)
{
    return v < lo ? lo : v > hi ? hi : v;
}

static int cell_x(const sense *s, double x)
{
    return clampi((int)floor((x - s->x0) / s->cell), 0, s->nx - 1);
}

static int cell_y(const sense *s, double y)
{
    return clampi((int)floor((y - s->y0) / s->cell), 0, s->ny - 1);
}

/* The bounding box of shape id, in cells. */
static void cells_of(const sense *s, int id, int *cx0, int *cy0, int *cx1, int *cy1)
{
    double ax, ay, bx, by;
    if (id >= 0) {
        const segment *g = &s->segs[id];
        ax = fmin(g->x1, g->x2); bx = fmax(g->x1, g->x2);
        ay = fmin(g->y1, g->y2); by = fmax(g->y1, g->y2);
    } else {
        const circle *c = &s->circles[~id];
        ax = c->x - c->r; bx = c->x + c->r;
        ay = c->y - c->r; by = c->y + c->r;
    }
    *cx0 = cell_x(s, ax); *cx1 = cell_x(s, bx);
    *cy0 = cell_y(s, ay); *cy1 = cell_y(s, by);
}

/* File ids[0..n) by counting sort over cells. */
static void file(sense *s, filing *f, const int *ids, int n)
{
    int cells = s->nx * s->ny, i, x, y, x0, y0, x1, y1, total = 0;
    memset(s->count, 0, (cells + 1) * sizeof(int));
    for (i = 0; i < n; i++) {
        cells_of(s, ids[i], &x0, &y0, &x1, &y1);
        for (y = y0; y <= y1; y++)
            for (x = x0; x <= x1; x++)
                s->count[y * s->nx + x]++;
    }
    for (i = 0; i < cells; i++) {
        f->start[i] = total;
        total += s->count[i];
        s->count[i] = f->start[i];
    }
    f->start[cells] = total;
    if (total > f->capids) {
        f->capids = total * 2;
        f->ids = xrealloc(f->ids, f->capids * sizeof(int));
    }
    for (i = 0; i < n; i++) {
        cells_of(s, ids[i], &x0, &y0, &x1, &y1);
        for (y = y0; y <= y1; y++)
            for (x = x0; x <= x1; x++)
                f->ids[s->count[y * s->nx + x]++] = ids[i];
    }
    f->nids = total;
}

static int add_segment(sense *s, double x1, double y1, double x2, double y2)
{
    s->segs = xrealloc(s->segs, (s->nsegs + 1) * sizeof *s->segs);
    s->segs[s->nsegs] = (segment){ x1, y1, x2, y2 };
    return s->nsegs++;
}

/* The four edges of a w x d rectangle at pose, into segs[first..first+4). */
static void rectangle(segment *segs, pose at, double w, double d)
{
    double h = at.heading * M_PI / 180, c = cos(h), sn = sin(h);
    double cx[4] = { w / 2, -w / 2, -w / 2, w / 2 }, cy[4] = { d / 2, d / 2, -d / 2, -d / 2 };
    double px[4], py[4];
    int i;
    for (i = 0; i < 4; i++) {
        px[i] = at.x + cx[i] * c - cy[i] * sn;
        py[i] = at.y + cx[i] * sn + cy[i] * c;
    }
    for (i = 0; i < 4; i++)
        segs[i] = (segment){ px[i], py[i], px[(i + 1) % 4], py[(i + 1) % 4] };
}

void sense_add_wall(sense *s, double x1, double y1, double x2, double y2, double thick)
{
    /* walls come before any box, so the wall filing is rebuilt only here */
    double dx = x2 - x1, dy = y2 - y1;
    pose at = { (x1 + x2) / 2, (y1 + y2) / 2, atan2(dy, dx) * 180 / M_PI };
    int i, first = s->nsegs, *ids;
    for (i = 0; i < 4; i++)
        add_segment(s, 0, 0, 0, 0);
    rectangle(&s->segs[first], at, hypot(dx, dy) + thick, thick);
    s->nwall_segs = s->nsegs;
    ids = xrealloc(NULL, s->nwall_segs * sizeof(int));
    for (i = 0; i < s->nwall_segs; i++)
        ids[i] = i;
    file(s, &s->walls, ids, s->nwall_segs);
    free(ids);
}

int sense_add_box(sense *s, double w, double d)
{
    int i;
    s->boxes = xrealloc(s->boxes, (s->nboxes + 1) * sizeof *s->boxes);
    s->boxes[s->nboxes] = (box){ w, d, { 0, 0, 0 }, 1 };
    for (i = 0; i < 4; i++)
        add_segment(s, 0, 0, 0, 0);
    return s->nboxes++;
}

int sense_add_circle(sense *s, double radius)
{
    s->circles = xrealloc(s->circles, (s->ncircles + 1) * sizeof *s->circles);
    s->circles[s->ncircles] = (circle){ 0, 0, radius, 1 };
    return s->ncircles++;
}

static int same(double a, double b)
{
    return fabs(a - b) < 0.01;
}

void sense_place_box(sense *s, int i, pose at)
{
    box *b = &s->boxes[i];
    if (same(b->at.x, at.x) && same(b->at.y, at.y) && same(b->at.heading, at.heading))
        return;
    b->at = at;
    b->moved = 1;
}

void sense_place_circle(sense *s, int i, double x, double y)
{
    circle *c = &s->circles[i];
    if (same(c->x, x) && same(c->y, y))
        return;
    c->x = x;
    c->y = y;
    c->moved = 1;
}

static void stamp(sense *s, int id, int step)
{
    int x, y, x0, y0, x1, y1;
    cells_of(s, id, &x0, &y0, &x1, &y1);
    for (y = y0; y <= y1; y++)
        for (x = x0; x <= x1; x++)
            s->changed[y * s->nx + x] = step;
}

void sense_refile(sense *s, int step)
{
    int n = s->ncircles + 4 * s->nboxes, k = 0, i, j;
    int *ids = xrealloc(NULL, n * sizeof(int));
    for (i = 0; i < s->nboxes; i++) {
        int first = s->nwall_segs + 4 * i;
        if (s->boxes[i].moved) {
            for (j = 0; j < 4; j++)
                stamp(s, first + j, step);
            rectangle(&s->segs[first], s->boxes[i].at, s->boxes[i].w, s->boxes[i].d);
            for (j = 0; j < 4; j++)
                stamp(s, first + j, step);
            s->boxes[i].moved = 0;
        }
        for (j = 0; j < 4; j++)
            ids[k++] = first + j;
    }
    for (i = 0; i < s->ncircles; i++)
        ids[k++] = ~i;
    /* circles were moved before their old cells could be stamped; stamp
     * generously instead: the cells around the new place include the old
     * ones, as nothing moves a cell in one step */
    for (i = 0; i < s->ncircles; i++)
        if (s->circles[i].moved) {
            circle *c = &s->circles[i];
            double r = c->r;
            c->r = r + s->cell;
            stamp(s, ~i, step);
            c->r = r;
            c->moved = 0;
        }
    file(s, &s->moving, ids, k);
    free(ids);
}

/* Ray (ox, oy) + t (dx, dy), |d| = 1: the t of the first hit, or `best`. */
static double hit_segment(const segment *g, double ox, double oy, double dx, double dy, double best)
{
    double ex = g->x2 - g->x1, ey = g->y2 - g->y1;
    double den = dx * ey - dy * ex, t, u;
    if (fabs(den) < 1e-12)
        return best;
    t = ((g->x1 - ox) * ey - (g->y1 - oy) * ex) / den;
    u = ((g->x1 - ox) * dy - (g->y1 - oy) * dx) / den;
    return t >= 0 && t < best && u >= 0 && u <= 1 ? t : best;
}

static double hit_circle(const circle *c, double ox, double oy, double dx, double dy, double best)
{
    double fx = ox - c->x, fy = oy - c->y;
    double b = fx * dx + fy * dy, q = fx * fx + fy * fy - c->r * c->r, disc, t;
    if (q <= 0)
        return 0;               /* starts inside: touching */
    disc = b * b - q;
    if (b > 0 || disc < 0)
        return best;
    t = -b - sqrt(disc);
    return t < best ? t : best;
}

static double hit_cell(const sense *s, const filing *f, int cell, int self,
                       double ox, double oy, double dx, double dy, double best)
{
    int k;
    for (k = f->start[cell]; k < f->start[cell + 1]; k++) {
        int id = f->ids[k];
        if (id >= 0)
            best = hit_segment(&s->segs[id], ox, oy, dx, dy, best);
        else if (~id != self)
            best = hit_circle(&s->circles[~id], ox, oy, dx, dy, best);
    }
    return best;
}

double sense_ray(const sense *s, int self, double x, double y, double dir_deg, double range)
{
    double h = dir_deg * M_PI / 180, dx = cos(h), dy = sin(h);
    int cx = cell_x(s, x), cy = cell_y(s, y);
    int stepx = dx > 0 ? 1 : -1, stepy = dy > 0 ? 1 : -1;
    /* t at which the ray crosses the next vertical / horizontal cell line */
    double nextx = s->x0 + (cx + (dx > 0)) * s->cell, nexty = s->y0 + (cy + (dy > 0)) * s->cell;
    double tx = fabs(dx) < 1e-12 ? INFINITY : (nextx - x) / dx;
    double ty = fabs(dy) < 1e-12 ? INFINITY : (nexty - y) / dy;
    double ddx = fabs(dx) < 1e-12 ? INFINITY : s->cell / fabs(dx);
    double ddy = fabs(dy) < 1e-12 ? INFINITY : s->cell / fabs(dy);
    double best = range;
    for (;;) {
        int cell = cy * s->nx + cx;
        double exit = fmin(tx, ty);
        best = hit_cell(s, &s->walls, cell, self, x, y, dx, dy, best);
        best = hit_cell(s, &s->moving, cell, self, x, y, dx, dy, best);
        if (best <= exit || exit >= range)
            return best;
        if (tx < ty) {
            cx += stepx;
            tx += ddx;
            if (cx < 0 || cx >= s->nx)
                return best;
        } else {
            cy += stepy;
            ty += ddy;
            if (cy < 0 || cy >= s->ny)
                return best;
        }
    }
}

int sense_still(const sense *s, double x, double y, double reach, int since)
{
    int x0 = cell_x(s, x - reach), x1 = cell_x(s, x + reach);
    int y0 = cell_y(s, y - reach), y1 = cell_y(s, y + reach), cx, cy;
    for (cy = y0; cy <= y1; cy++)
        for (cx = x0; cx <= x1; cx++)
            if (s->changed[cy * s->nx + cx] >= since)
                return 0;
    return 1;
}
