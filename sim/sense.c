#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "sense.h"
#include "alloc.h"

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
    filing cells;               /* everything, refiled each step */
    int *changed;               /* per cell: last step something moved there */
    int *count;                 /* scratch for filing */
};

sense *sense_new(double x0, double y0, double x1, double y1, double cell)
{
    sense *s = xcalloc(1, sizeof *s);
    int cells;
    s->x0 = x0;
    s->y0 = y0;
    s->cell = cell;
    s->nx = (int)ceil((x1 - x0) / cell) + 1;
    s->ny = (int)ceil((y1 - y0) / cell) + 1;
    cells = s->nx * s->ny;
    s->cells.start = xcalloc(cells + 1, sizeof(int));
    s->changed = xcalloc(cells, sizeof(int));
    s->count = xcalloc(cells + 1, sizeof(int));
    memset(s->changed, 0xff, cells * sizeof(int));   /* -1: never */
    return s;
}

void sense_free(sense *s)
{
    free(s->segs);
    free(s->circles);
    free(s->boxes);
    free(s->cells.start);
    free(s->cells.ids);
    free(s->changed);
    free(s->count);
    free(s);
}

static void *copy(void *to, const void *from, size_t n)
{
    return memcpy(xrealloc(to, n), from, n);
}

sense *sense_snapshot(sense *into, const sense *from)
{
    sense kept;
    int cells = from->nx * from->ny;
    if (!into)
        into = xcalloc(1, sizeof *into);
    kept = *into;
    *into = *from;
    into->segs = copy(kept.segs, from->segs, from->nsegs * sizeof *from->segs);
    into->circles = copy(kept.circles, from->circles, from->ncircles * sizeof *from->circles);
    into->boxes = copy(kept.boxes, from->boxes, from->nboxes * sizeof *from->boxes);
    into->cells.start = copy(kept.cells.start, from->cells.start, (cells + 1) * sizeof(int));
    into->cells.ids = copy(kept.cells.ids, from->cells.ids, from->cells.nids * sizeof(int));
    into->cells.capids = from->cells.nids;
    into->changed = copy(kept.changed, from->changed, cells * sizeof(int));
    into->count = copy(kept.count, from->count, (cells + 1) * sizeof(int));
    return into;
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
        ax = lesser(g->x1, g->x2); bx = greater(g->x1, g->x2);
        ay = lesser(g->y1, g->y2); by = greater(g->y1, g->y2);
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
    /* walls come before any box: segs[0..nwall_segs) */
    double dx = x2 - x1, dy = y2 - y1;
    pose at = { (x1 + x2) / 2, (y1 + y2) / 2, atan2(dy, dx) * 180 / M_PI };
    int i, first = s->nsegs;
    for (i = 0; i < 4; i++)
        add_segment(s, 0, 0, 0, 0);
    rectangle(&s->segs[first], at, hypot(dx, dy) + thick, thick);
    s->nwall_segs = s->nsegs;
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

/* One filing for walls and moving shapes alike, so that a cast looks up
 * each cell once; walls are few enough to refile with the rest. */
void sense_refile(sense *s, int step)
{
    int n = s->nsegs + s->ncircles, k = 0, i, j;
    int *ids = xrealloc(NULL, n * sizeof(int));
    for (i = 0; i < s->nwall_segs; i++)
        ids[k++] = i;
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
    file(s, &s->cells, ids, k);
    free(ids);
}

void sense_scratch_free(sense_scratch *sc)
{
    free(sc->met);
    memset(sc, 0, sizeof *sc);
}

/* True the first time this cast meets shape id. */
static int first_meeting(const sense *s, sense_scratch *sc, int id)
{
    int k = id >= 0 ? id : s->nsegs + ~id;
    if (sc->met[k] == sc->cast)
        return 0;
    sc->met[k] = sc->cast;
    return 1;
}

static void start_cast(const sense *s, sense_scratch *sc)
{
    int shapes = s->nsegs + s->ncircles;
    if (shapes > sc->cap || ++sc->cast == 0) {
        sc->cap = shapes > sc->cap ? shapes : sc->cap;
        free(sc->met);
        sc->met = xcalloc(sc->cap, sizeof *sc->met);
        sc->cast = 1;
    }
}

/* A stand-in for atan2 that grows with the angle over [0, 4) and costs no
 * trigonometry: rays and shapes are only compared by it. */
static double pseudo_angle(double x, double y)
{
    if (y >= 0)
        return x >= 0 ? (x + y > 0 ? y / (x + y) : 0) : 1 - x / (y - x);
    return x < 0 ? 2 - y / (-x - y) : 3 + x / (x - y);
}

/* Sort the rays by pseudo-angle: they go round counter-clockwise, so this
 * is a rotation of their order.  The list is kept twice over, so that an
 * arc across angle 0 is one run. */
static void order_rays(sense_scratch *sc, const double *dx, const double *dy, int n)
{
    int k, first = 0;
    double a[SENSE_MAX_RAYS];
    for (k = 0; k < n; k++) {
        a[k] = pseudo_angle(dx[k], dy[k]);
        if (a[k] < a[first])
            first = k;
    }
    for (k = 0; k < 2 * n; k++) {
        int r = (first + k) % n;
        sc->ray[k] = r;
        sc->angle[k] = a[r] + (k >= n ? 4 : 0);
    }
    sc->n = n;
}

/* The rays within the arc from pseudo-angle lo counter-clockwise to hi:
 * indices [*from, *to) of sc->ray. */
static void arc(const sense_scratch *sc, double lo, double hi, int *from, int *to)
{
    int a = 0, b = sc->n;
    if (hi < lo)
        hi += 4;
    while (a < b) {             /* first angle >= lo */
        int m = (a + b) / 2;
        if (sc->angle[m] < lo)
            a = m + 1;
        else
            b = m;
    }
    *from = a;
    for (b = a; b < a + sc->n && sc->angle[b] <= hi; b++)
        ;
    *to = b;
}

/* The rays that meet a segment: solve origin + t d = p1 + u (p2 - p1). */
static void fan_segment(const segment *g, const sense_scratch *sc, double x, double y,
                        const double *dx, const double *dy, double *out)
{
    double ax = g->x1 - x, ay = g->y1 - y, bx = g->x2 - x, by = g->y2 - y;
    double ex = bx - ax, ey = by - ay, tn = ax * ey - ay * ex, cross = ax * by - ay * bx;
    int i, from, to;
    if (cross == 0)
        return;                 /* seen edge on */
    if (cross > 0)
        arc(sc, pseudo_angle(ax, ay), pseudo_angle(bx, by), &from, &to);
    else
        arc(sc, pseudo_angle(bx, by), pseudo_angle(ax, ay), &from, &to);
    for (i = from; i < to; i++) {
        int k = sc->ray[i];
        double den = dx[k] * ey - dy[k] * ex, t = tn / den;
        if (den != 0 && t >= 0 && t < out[k])
            out[k] = t;
    }
}

/* The rays that meet a circle, between its two tangents; none when the
 * origin is inside it. */
static void fan_circle(const circle *c, const sense_scratch *sc, double x, double y,
                       const double *dx, const double *dy, double *out)
{
    double vx = c->x - x, vy = c->y - y, d2 = vx * vx + vy * vy, r2 = c->r * c->r, h;
    int i, from, to;
    if (d2 <= r2)
        return;
    h = sqrt(d2 - r2);          /* tangents: v turned by +-asin(r/d), scaled by d */
    arc(sc, pseudo_angle(vx * h + vy * c->r, vy * h - vx * c->r),
        pseudo_angle(vx * h - vy * c->r, vy * h + vx * c->r), &from, &to);
    for (i = from; i < to; i++) {
        int k = sc->ray[i];
        double b = vx * dx[k] + vy * dy[k], disc = b * b - d2 + r2;
        if (disc >= 0 && b - sqrt(disc) < out[k])
            out[k] = b - sqrt(disc);
    }
}

static void fan_cell(const sense *s, sense_scratch *sc, int cell, int self,
                     double x, double y, const double *dx, const double *dy, double *out)
{
    const filing *f = &s->cells;
    int k;
    for (k = f->start[cell]; k < f->start[cell + 1]; k++) {
        int id = f->ids[k];
        if (id == ~self || !first_meeting(s, sc, id))
            continue;
        if (id >= 0)
            fan_segment(&s->segs[id], sc, x, y, dx, dy, out);
        else
            fan_circle(&s->circles[~id], sc, x, y, dx, dy, out);
    }
}

static double longest(const double *out, int n)
{
    double m = 0;
    int k;
    for (k = 0; k < n; k++)
        m = out[k] > m ? out[k] : m;
    return m;
}

/* The square of how far (x, y) is from cell (i, j): 0 inside it. */
static double cell_distance2(const sense *s, int i, int j, double x, double y)
{
    double ex = fabs(x - (s->x0 + (i + 0.5) * s->cell)) - s->cell / 2;
    double ey = fabs(y - (s->y0 + (j + 0.5) * s->cell)) - s->cell / 2;
    ex = ex > 0 ? ex : 0;
    ey = ey > 0 ? ey : 0;
    return ex * ex + ey * ey;
}

void sense_fan(const sense *s, sense_scratch *sc, int self, double x, double y,
               const double *dx, const double *dy, int n, double range, double *out)
{
    int cx = cell_x(s, x), cy = cell_y(s, y), ring, k;
    double reach = range;
    start_cast(s, sc);
    order_rays(sc, dx, dy, n);
    for (k = 0; k < n; k++)
        out[k] = range;
    /* every cell of ring r+1 is at least r cells away from (x, y); within a
     * ring, cells beyond the longest ray still unanswered are skipped */
    for (ring = 0; ring == 0 || (ring - 1) * s->cell < (reach = longest(out, n)); ring++) {
        int x0 = cx - ring, x1 = cx + ring, y0 = cy - ring, y1 = cy + ring, i, j;
        if (x0 < 0 && y0 < 0 && x1 >= s->nx && y1 >= s->ny)
            break;
        for (j = y0 > 0 ? y0 : 0; j <= y1 && j < s->ny; j++) {
            int step = (j == y0 || j == y1) ? 1 : x1 - x0;   /* only the ring's edge */
            for (i = x0; i <= x1; i += step > 0 ? step : 1)
                if (i >= 0 && i < s->nx && (ring < 2 || cell_distance2(s, i, j, x, y) < reach * reach))
                    fan_cell(s, sc, j * s->nx + i, self, x, y, dx, dy, out);
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
