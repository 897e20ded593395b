#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "trace.h"
#include "alloc.h"

enum { SAMPLE_HZ = 10, SONAR_HZ = 5, MAX_SONARS = 5000, MAX_SAYS = 1000 };

typedef struct { double t; pose at; double ranges[SONARS]; int robot; } sonar_event;
typedef struct { double t; pose at; char *text; int robot; } say_event;

struct trace {
    char *path;
    pose *samples;              /* per sample: robots, then boxes */
    int nsamples, capsamples, width;
    sonar_event *sonars;
    int nsonars;
    double *last_sonar;         /* per robot: time of its last drawn reading */
    say_event *says;
    int nsays;
};

struct trace *trace_open(const char *path)
{
    struct trace *t = xcalloc(1, sizeof *t);
    t->path = xstrdup(path);
    t->sonars = xmalloc(MAX_SONARS * sizeof *t->sonars);
    t->says = xmalloc(MAX_SAYS * sizeof *t->says);
    return t;
}

void trace_step(struct trace *t, const world *w)
{
    int every = (int)fmax(1, w->lab->step_hz / SAMPLE_HZ), i;
    pose *row;
    if ((w->step - 1) % every != 0)
        return;
    t->width = w->nrobots + w->lab->nboxes;
    if (t->nsamples == t->capsamples) {
        t->capsamples = t->capsamples ? 2 * t->capsamples : 256;
        t->samples = xrealloc(t->samples, (size_t)t->capsamples * t->width * sizeof(pose));
    }
    row = &t->samples[(size_t)t->nsamples++ * t->width];
    for (i = 0; i < w->nrobots; i++)
        row[i] = w->robots[i].at;
    for (i = 0; i < w->lab->nboxes; i++)
        row[w->nrobots + i] = physics_box_pose(w->phys, i);
}

void trace_sonar(struct trace *t, const world *w, int r)
{
    double now = w->robots[r].ss.step * w->dt;   /* when it fired */
    sonar_event *e;
    if (!t->last_sonar) {
        int i;
        t->last_sonar = xmalloc((w->nrobots + 1) * sizeof(double));
        for (i = 0; i < w->nrobots; i++)
            t->last_sonar[i] = -1;
    }
    if (t->nsonars == MAX_SONARS || (t->last_sonar[r] >= 0 && now - t->last_sonar[r] < 1.0 / SONAR_HZ))
        return;
    t->last_sonar[r] = now;
    e = &t->sonars[t->nsonars++];
    e->t = now;
    e->at = w->robots[r].ss.at;
    e->robot = r;
    memcpy(e->ranges, w->robots[r].sonar, sizeof e->ranges);
}

/* The trace reads the world it is shown but calls nothing of world.c:
 * the world calls the trace (through its observer), never the reverse. */
static double seconds(const world *w)
{
    return w->step * w->dt;
}

void trace_say(struct trace *t, const world *w, int r, const char *text)
{
    if (t->nsays == MAX_SAYS)
        return;
    t->says[t->nsays++] = (say_event){ seconds(w), w->robots[r].at, xstrdup(text), r };
}

/* Robot r's colour: that of its address space's place in the lab file,
 * from the live view's palette (web/view.js COLOURS, the same list), so
 * that a robot has one colour in both pictures. */
static const char *colour(const world *w, int r)
{
    static const char *c[] = { "#1565c0", "#c62828", "#2e7d32", "#6a1b9a", "#ef6c00",
                               "#00838f", "#4e342e", "#ad1457", "#558b2f", "#283593" };
    return c[w->lab->robots[r].aspace % 10];
}

static void xml_text(FILE *f, const char *s)
{
    for (; *s; s++)
        switch (*s) {
        case '<': fputs("&lt;", f); break;
        case '>': fputs("&gt;", f); break;
        case '&': fputs("&amp;", f); break;
        default: fputc(*s, f);
        }
}

/* Column k of the samples as a moving group: placed where it starts (for
 * viewers that do not animate), then translated and, in an inner group,
 * rotated through every sample.  The caller closes both groups. */
static void animate(FILE *f, const struct trace *t, int k, double dur)
{
    const pose *first = &t->samples[k];
    int s;
    fprintf(f, "<g transform=\"translate(%.0f,%.0f)\"><animateTransform attributeName=\"transform\" type=\"translate\" dur=\"%.2fs\" fill=\"freeze\" values=\"",
            first->x, first->y, dur);
    for (s = 0; s < t->nsamples; s++)
        fprintf(f, "%s%.0f,%.0f", s ? ";" : "", t->samples[(size_t)s * t->width + k].x,
                t->samples[(size_t)s * t->width + k].y);
    fprintf(f, "\"/><g transform=\"rotate(%.1f)\"><animateTransform attributeName=\"transform\" type=\"rotate\" dur=\"%.2fs\" fill=\"freeze\" values=\"",
            first->heading, dur);
    for (s = 0; s < t->nsamples; s++)
        fprintf(f, "%s%.1f", s ? ";" : "", t->samples[(size_t)s * t->width + k].heading);
    fputs("\"/>", f);
}

static void write_walls(FILE *f, const lab *l)
{
    int i;
    for (i = 0; i < l->nwalls; i++)
        fprintf(f, "<line x1=\"%g\" y1=\"%g\" x2=\"%g\" y2=\"%g\" stroke=\"#444\" stroke-width=\"%g\" stroke-linecap=\"square\"/>\n",
                l->walls[i].x1, l->walls[i].y1, l->walls[i].x2, l->walls[i].y2, l->walls[i].thick);
}

static void write_paths(FILE *f, const struct trace *t, const world *w)
{
    int i, s;
    for (i = 0; i < w->nrobots; i++) {
        fprintf(f, "<polyline fill=\"none\" stroke=\"%s\" stroke-opacity=\"0.5\" stroke-width=\"40\" points=\"", colour(w, i));
        for (s = 0; s < t->nsamples; s++)
            fprintf(f, "%.0f,%.0f ", t->samples[(size_t)s * t->width + i].x, t->samples[(size_t)s * t->width + i].y);
        fputs("\"/>\n", f);
    }
}

static void write_bodies(FILE *f, const struct trace *t, const world *w, double dur)
{
    int i;
    for (i = 0; i < w->lab->nboxes; i++) {
        const lab_box *b = &w->lab->boxes[i];
        animate(f, t, w->nrobots + i, dur);
        fprintf(f, "<rect x=\"%g\" y=\"%g\" width=\"%g\" height=\"%g\" fill=\"#c8a165\" stroke=\"#7a5c2e\" stroke-width=\"15\"/></g></g>\n",
                -b->w / 2, -b->d / 2, b->w, b->d);
    }
    for (i = 0; i < w->nrobots; i++) {
        double r = w->lab->b14.radius;
        animate(f, t, i, dur);
        fprintf(f, "<circle r=\"%g\" fill=\"%s\" fill-opacity=\"0.8\"/><line x1=\"0\" y1=\"0\" x2=\"%g\" y2=\"0\" stroke=\"white\" stroke-width=\"30\"/></g>",
                r, colour(w, i), r);
        /* its name, beside it and the right way up, as the view writes it */
        fprintf(f, "<text transform=\"scale(1,-1)\" x=\"%g\" y=\"%g\" font-size=\"220\" fill=\"%s\">",
                r + 40, -r - 40, colour(w, i));
        xml_text(f, w->robots[i].name);
        fputs("</text></g>\n", f);
    }
}

static void write_sonars(FILE *f, const struct trace *t, const world *w)
{
    const b14_params *p = &w->lab->b14;
    int e, k;
    for (e = 0; e < t->nsonars; e++) {
        const sonar_event *s = &t->sonars[e];
        fprintf(f, "<g visibility=\"hidden\" fill=\"%s\" fill-opacity=\"0.15\"><set attributeName=\"visibility\" to=\"visible\" begin=\"%.2fs\" dur=\"%.2fs\"/>",
                colour(w, s->robot), s->t, 1.0 / SONAR_HZ);
        for (k = 0; k < SONARS; k++) {
            double a = (s->at.heading + 22.5 * k - p->sonar_cone / 2) * M_PI / 180;
            double b = (s->at.heading + 22.5 * k + p->sonar_cone / 2) * M_PI / 180;
            double r = s->ranges[k] + p->radius;
            fprintf(f, "<path d=\"M%.0f %.0fL%.0f %.0fA%.0f %.0f 0 0 1 %.0f %.0fZ\"/>", s->at.x, s->at.y,
                    s->at.x + r * cos(a), s->at.y + r * sin(a), r, r, s->at.x + r * cos(b), s->at.y + r * sin(b));
        }
        fputs("</g>\n", f);
    }
}

/* Speech is drawn outside the flipped group, so text reads the right way up. */
static void write_says(FILE *f, const struct trace *t, const world *w)
{
    int e;
    for (e = 0; e < t->nsays; e++) {
        const say_event *s = &t->says[e];
        fprintf(f, "<text x=\"%.0f\" y=\"%.0f\" font-size=\"250\" fill=\"%s\" visibility=\"hidden\"><set attributeName=\"visibility\" to=\"visible\" begin=\"%.2fs\" dur=\"3s\"/>%s: ",
                s->at.x + 250, -s->at.y - 250, colour(w, s->robot), s->t, w->robots[s->robot].name);
        xml_text(f, s->text);
        fputs("</text>\n", f);
    }
}

static void bounds(const world *w, double *x0, double *y0, double *x1, double *y1)
{
    const lab *l = w->lab;
    int i;
    *x0 = *y0 = -5000;
    *x1 = *y1 = 5000;
    for (i = 0; i < l->nwalls; i++) {
        *x0 = fmin(*x0, fmin(l->walls[i].x1, l->walls[i].x2));
        *x1 = fmax(*x1, fmax(l->walls[i].x1, l->walls[i].x2));
        *y0 = fmin(*y0, fmin(l->walls[i].y1, l->walls[i].y2));
        *y1 = fmax(*y1, fmax(l->walls[i].y1, l->walls[i].y2));
    }
}

static void observe_step(void *t, const world *w) { trace_step(t, w); }
static void observe_sonar(void *t, const world *w, int r) { trace_sonar(t, w, r); }
static void observe_say(void *t, const world *w, int r, const char *text)
{
    trace_say(t, w, r, text);
}

world_observer trace_observer(struct trace *t)
{
    return (world_observer){ t, observe_step, observe_sonar, observe_say };
}

int trace_close(struct trace *t, const world *w)
{
    size_t n = strlen(t->path) + 8;
    char *tmp = xmalloc(n);
    double x0, y0, x1, y1, dur = fmax(t->nsamples, 2) / (double)SAMPLE_HZ;
    FILE *f;
    int e, rc = -1;
    snprintf(tmp, n, "%s.tmp", t->path);
    bounds(w, &x0, &y0, &x1, &y1);
    if ((f = fopen(tmp, "w"))) {
        fprintf(f, "<?xml version=\"1.0\"?>\n<svg xmlns=\"http://www.w3.org/2000/svg\" viewBox=\"%.0f %.0f %.0f %.0f\" width=\"800\" height=\"%.0f\">\n",
                x0 - 500, -y1 - 500, x1 - x0 + 1000, y1 - y0 + 1000, 800 * (y1 - y0 + 1000) / (x1 - x0 + 1000));
        fprintf(f, "<title>b14 trace, %.1f s simulated</title>\n<rect x=\"%.0f\" y=\"%.0f\" width=\"100%%\" height=\"100%%\" fill=\"#f4f1ea\"/>\n",
                seconds(w), x0 - 500, -y1 - 500);
        fputs("<g transform=\"scale(1,-1)\">\n", f);
        write_walls(f, w->lab);
        if (t->nsamples > 0) {
            write_paths(f, t, w);
            write_sonars(f, t, w);
            write_bodies(f, t, w, dur);
        }
        fputs("</g>\n", f);
        write_says(f, t, w);
        fputs("</svg>\n", f);
        rc = fclose(f) == 0 && rename(tmp, t->path) == 0 ? 0 : -1;
    }
    if (rc)
        perror(t->path);
    for (e = 0; e < t->nsays; e++)
        free(t->says[e].text);
    free(t->says);
    free(t->sonars);
    free(t->samples);
    free(t->last_sonar);
    free(t->path);
    free(tmp);
    free(t);
    return rc;
}
