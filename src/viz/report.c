/* report.c: the one-file HTML report (--report): the part, its poses'
 * table, the gallery, chart and sphere inline, the run's settings, timings
 * and the command that reproduces it. No script and nothing loaded from
 * elsewhere, so the file opens anywhere and prints as it shows. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "base/fail.h"
#include "viz/viz_internal.h"

static const char *const style =
    "body{font-family:'DejaVu Sans',Helvetica,Arial,sans-serif;color:#111;margin:0 auto;"
    "max-width:1240px;padding:16px 20px;line-height:1.4}\n"
    "h1{font-size:1.5em;margin:0.2em 0}.size{font-size:1.15em;margin:0.3em 0}h2{font-size:1.2em;border-bottom:1px solid #ccc;"
    "padding-bottom:2px;margin-top:1.4em}\n"
    "table{border-collapse:collapse;margin:0.4em 0}td,th{border:1px solid #ccc;padding:2px 8px;"
    "text-align:right;font-variant-numeric:tabular-nums}th{background:#f2f2f2}\n"
    "td{white-space:nowrap}td.l{white-space:normal}\n"
    "td.l,th.l{text-align:left}.note{color:#555;font-size:0.9em}\n"
    "figure{margin:0.6em 0}svg{max-width:100%;height:auto}\n"
    "pre{background:#f6f6f6;padding:8px;white-space:pre-wrap;word-break:break-all}\n"
    "@media print{body{max-width:none;padding:0}section{break-inside:avoid}"
    "figure{break-inside:avoid}h2{break-after:avoid}}\n";

static void row(vbuf *b, const char *key, const char *value)
{
    vbuf_put(b, "<tr><th class=\"l\">");
    vbuf_escape(b, key);
    vbuf_put(b, "</th><td class=\"l\">");
    vbuf_escape(b, value);
    vbuf_put(b, "</td></tr>\n");
}

/* A length in m shown in mm below 1 m, else in m. */
static void length(char *out, size_t size, double m)
{
    if (fabs(m) < 1.0)
        snprintf(out, size, "%.4g mm", 1000.0 * m);
    else
        snprintf(out, size, "%.6g m", m);
}

/* An argument as a POSIX shell reads it back: bare when it holds only safe
 * characters, else single-quoted. */
static void shell_word(vbuf *b, const char *s)
{
    int safe = *s != '\0';
    for (const char *p = s; *p; p++)
        if (!strchr("abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789_./,:=+-@%", *p))
            safe = 0;
    if (safe) {
        vbuf_escape(b, s);
        return;
    }
    vbuf_put(b, "&#39;");
    for (const char *p = s; *p; p++) {
        if (*p == '\'') {
            vbuf_put(b, "&#39;\\&#39;&#39;");
        } else {
            char c[2] = {*p, 0};
            vbuf_escape(b, c);
        }
    }
    vbuf_put(b, "&#39;");
}

static void part_section(vbuf *b, const viz_input *in, const viz_run *run)
{
    const pd_part *part = in->part;
    char v[256];
    static const char *const units[] = {"m", "cm", "mm", "in"};
    vbuf_put(b, "<section id=\"part\"><h2>Part</h2>\n<table>\n");
    row(b, "file", run->path);
    row(b, "units of the file", units[run->units]);
    length(v, sizeof v, part->size);
    row(b, "size (bounding-box diagonal)", v);
    snprintf(v, sizeof v, "%d vertices, %d triangles, %s", part->mesh->nverts,
             part->mesh->ntris, part->closed ? "closed" : "not closed");
    row(b, "mesh (welded)", v);
    if (part->mass_known) {
        snprintf(v, sizeof v, "%.6g mm\xc2\xb3 of uniform density: mass = density \xc3\x97 volume",
                 part->mass.volume * 1e9);
        row(b, "volume", v);
    } else {
        row(b, "volume", "unknown (mesh not closed; centre of mass given)");
    }
    /* Round-off of a centred part (1e-18 m) shown as 0: a millionth of the
     * size is below every digit printed. */
    double c[3] = {part->com.x, part->com.y, part->com.z};
    for (int k = 0; k < 3; k++)
        c[k] = fabs(c[k]) < 1e-6 * part->size ? 0.0 : c[k];
    snprintf(v, sizeof v, "(%.6g, %.6g, %.6g) mm in the file's frame%s", 1000.0 * c[0],
             1000.0 * c[1], 1000.0 * c[2], part->mass_known ? "" : ", given");
    row(b, "centre of mass", v);
    snprintf(v, sizeof v, "%d facets, %d vertices; %d stable poses", part->hull->nfacets,
             part->hull->nverts, in->res->nposes);
    row(b, "convex hull", v);
    pd_symmetry *sym = NULL;
    pd_diag d;
    pd_diag_init(&d);
    if (pd_symmetry_find(part, &sym, &d) == PD_OK) {
        if (sym->capped)
            snprintf(v, sizeof v, "not searched (too many candidate frames)");
        else if (sym->nrotations == 1)
            snprintf(v, sizeof v, "none: the identity is the hull's only rotation");
        else
            snprintf(v, sizeof v, "%d proper rotations map the hull onto itself%s",
                     sym->nrotations, in->class_of ? "; poses grouped into classes" : "");
        row(b, "symmetry", v);
    }
    pd_symmetry_free(sym);
    vbuf_put(b, "</table></section>\n");
}

static void pct(vbuf *b, double p)
{
    vbuf_printf(b, "<td>%.2f%%</td>", 100.0 * p);
}

static void table_section(vbuf *b, const viz_input *in, const viz_entry *e, int n)
{
    vbuf_put(b, "<section id=\"table\"><h2>Estimates</h2>\n<table>\n<tr><th>pose</th>"
                "<th>gravity in the part's frame</th><th>height of the centre of mass</th>"
                "<th>QS</th><th>PQS</th>");
    if (e[0].has_dyn)
        vbuf_put(b, "<th>dynamic</th><th>95% interval</th>");
    if (e[0].has_xc) {
        for (int k = 0; k < VIZ_ENGINES; k++)
            vbuf_printf(b, "<th>%s</th>", viz_engine_label(k));
        vbuf_put(b, "<th>range across engines</th>");
    }
    if (e[0].has_meas)
        vbuf_put(b, "<th>measured</th>");
    vbuf_put(b, "</tr>\n");
    for (int i = 0; i < n; i++) {
        const pd_pose *p = &in->res->poses[e[i].pose];
        vbuf_printf(b, "<tr><td>%d%s</td><td>(%.4f, %.4f, %.4f)</td><td>%.4g mm</td>", e[i].number,
                    e[i].members > 1 ? " *" : "", p->normal.x + 0.0, p->normal.y + 0.0,
                    p->normal.z + 0.0, 1000.0 * p->height);
        pct(b, e[i].p_qs);
        pct(b, e[i].p_pqs);
        if (e[i].has_dyn) {
            pct(b, e[i].p);
            vbuf_printf(b, "<td>%.2f%% to %.2f%%</td>", 100.0 * e[i].lo, 100.0 * e[i].hi);
        }
        if (e[i].has_xc) {
            for (int k = 0; k < VIZ_ENGINES; k++) {
                const pd_sim_result *r = in->engines->sim[k];
                if (r && r->n > 0)
                    pct(b, r->p[i]);
                else
                    vbuf_put(b, "<td>not run</td>");
            }
            vbuf_printf(b, "<td>%.2f%% to %.2f%%%s</td>", 100.0 * e[i].x.lo, 100.0 * e[i].x.hi,
                        e[i].x.apart ? " !" : "");
        }
        if (e[i].has_meas)
            pct(b, e[i].mp);
        vbuf_put(b, "</tr>\n");
    }
    vbuf_put(b, "</table>\n");
    if (e[0].has_dyn && in->sim->unsettled > 0 && !in->sim->transitions)
        vbuf_printf(b, "<p class=\"note\">%ld of %ld drops did not settle (time or collision "
                       "limit, or a solver failed) and are in no pose's count: the dynamic "
                       "column sums to %.1f%%, not 100%%.</p>\n", in->sim->unsettled, in->sim->n,
                    100.0 * (double)(in->sim->n - in->sim->unsettled) / (double)in->sim->n);
    if (in->class_of)
        vbuf_put(b, "<p class=\"note\">* a class of poses that rotations of the part map onto "
                    "each other; its probabilities are summed, its geometry is its first "
                    "member's.</p>\n");
    if (e[0].has_meas) {
        vbuf_put(b, "<p class=\"note\">Against the measured distribution: ");
        static const char *const names[] = {"QS", "PQS", "dynamic"};
        for (int k = 0; k < 2 + e[0].has_dyn; k++) {
            double e16, tv;
            viz_eq16(e, n, k, &e16, &tv);
            vbuf_printf(b, "%s%s eq. (16) error %.2f, total variation %.1f%%", k ? "; " : "",
                        names[k], e16, tv);
        }
        vbuf_put(b, ".</p>\n");
    }
    vbuf_put(b, "</section>\n");
}

/* --crosscheck in words: whether the engines' 95% intervals are apart on
 * any pose, which, and what that means for the estimate. */
static void crosscheck_section(vbuf *b, const viz_input *in, const viz_entry *e, int n)
{
    const char *what = in->class_of ? "class" : "pose";
    int apart = 0, widest = 0, ran = 0;
    for (int i = 0; i < n; i++) {
        apart += e[i].x.apart;
        if (e[i].x.hi - e[i].x.lo > e[widest].x.hi - e[widest].x.lo)
            widest = i;
    }
    vbuf_put(b, "<section id=\"crosscheck\"><h2>The three engines</h2>\n<p>The same releases "
                "(drop i of the seed starts from the same state) were run on ");
    for (int k = 0; k < VIZ_ENGINES; k++) {
        const pd_sim_result *r = in->engines->sim[k];
        if (!r || r->n == 0)
            continue;
        vbuf_printf(b, "%s%s (%ld drops, %ld unsettled)", ran ? ", " : "", viz_engine_label(k),
                    r->n, r->unsettled);
        ran++;
    }
    vbuf_put(b, ". They model the same physics with different contacts, so their spread is the "
                "model's uncertainty, beside the sampling interval of each.</p>\n<p>");
    if (ran < 2) {
        vbuf_put(b, "Only one engine ran (the run was interrupted): nothing to compare.");
    } else if (!apart) {
        vbuf_printf(b, "<strong>The engines agree within their sampling intervals</strong>: "
                    "their 95%% intervals overlap on every %s. The widest range across them is "
                    "%.1f points, on %s %d.", what, 100.0 * (e[widest].x.hi - e[widest].x.lo),
                    what, e[widest].number);
    } else {
        vbuf_printf(b, "<strong>The engines disagree beyond their sampling intervals</strong> "
                    "on %d of %d %s%s (marked ! in the table and the chart): ", apart, n, what,
                    n == 1 ? "" : in->class_of ? "es" : "s");
        int shown = 0;
        for (int i = 0; i < n; i++) {
            if (!e[i].x.apart)
                continue;
            vbuf_printf(b, "%s%s %d from %.1f%% to %.1f%%", shown++ ? "; " : "", what,
                        e[i].number, 100.0 * e[i].x.lo, 100.0 * e[i].x.hi);
        }
        vbuf_put(b, ". There the contact model, not the number of drops, limits the estimate: "
                    "more drops will not narrow it; take the range across the engines as "
                    "what is known (docs/engines.md).");
    }
    vbuf_put(b, "</p></section>\n");
}

static void run_section(vbuf *b, const viz_run *run, const pd_part *part,
                        const pd_sim_result *sim, const pd_scene *scene, int crosscheck)
{
    char v[1024], contact[192];
    vbuf_put(b, "<section id=\"run\"><h2>Scene, engine and timings</h2>\n<table>\n");
    const pd_static_options *o = run->estimate;
    snprintf(v, sizeof v, "topple %s; PQS epsilon %.4g deg, compare %s, band %s",
             o->topple == PD_TOPPLE_DESCENT ? "descent" : "edge", o->epsilon * (180.0 / M_PI),
             o->compare == PD_PQS_COMPARE_RAW ? "raw" : "qs", o->band == PD_PQS_BAND_RECT ? "rect" : "exact");
    row(b, "static estimators", v);
    if (scene && sim) {
        const pd_scene *s = scene;
        char p[PD_NPARAMS][64];
        for (int k = 0; k < PD_NPARAMS; k++)
            pd_scene_format(s, (pd_scene_param)k, p[k], sizeof p[k]);
        /* The automatic contact time by name and with the value it stands
         * for here (the scene holds a code for it, not a duration). */
        const pd_dist *ct = &s->range[PD_PARAM_CONTACT_TIME];
        double auto_s = pd_contact_time_auto(pd_contact_time_auto_size(part));
        if (ct->kind == PD_DIST_FIXED && s->contact_time == PD_CONTACT_TIME_AUTO)
            snprintf(contact, sizeof contact, "auto (%.4g s for this part's size and volume)", auto_s);
        else if (ct->auto_multiple)
            snprintf(contact, sizeof contact, "%s times auto (%.4g s for this part's size and volume)",
                     p[PD_PARAM_CONTACT_TIME], auto_s);
        else
            snprintf(contact, sizeof contact, "%s s%s", p[PD_PARAM_CONTACT_TIME],
                     ct->kind == PD_DIST_FIXED && s->contact_time == 0.0 ? " (rigid)" : "");
        snprintf(v, sizeof v, "drop height %s m, belt %s m/s, mu %s, restitution %s (%s), "
                 "vibration %s deg, gravity %.4g m/s\xc2\xb2, contact time %s, tumble %s rad/s, "
                 "initial %s%s", p[PD_PARAM_HEIGHT], p[PD_PARAM_BELT_SPEED], p[PD_PARAM_MU],
                 p[PD_PARAM_RESTITUTION], s->law == PD_RESTITUTION_POISSON ? "Poisson" : "energetic",
                 p[PD_PARAM_VIBRATION], s->gravity, contact, p[PD_PARAM_TUMBLE],
                 viz_initial_name(s->initial),
                 pd_scene_ranged(s) ? "; LO:HI: a range, each drop drawing its own value" : "");
        row(b, "scene", v);
        static const char *const engines[] = {"impulse (posedrop's own)", "ODE", "Bullet"};
        const pd_sim_options *so = run->sim;
        if (so->engine == PD_ENGINE_IMPULSE)
            snprintf(v, sizeof v, "%s; seed %llu", engines[so->engine], (unsigned long long)so->seed);
        else
            snprintf(v, sizeof v, "%s, time step %s; seed %llu", engines[so->engine],
                     so->dt > 0 ? "as given" : "automatic, from the scene",
                     (unsigned long long)so->seed);
        if (crosscheck)
            snprintf(v + strlen(v), sizeof v - strlen(v), "; the same releases on every engine "
                     "(--crosscheck), ODE and Bullet at %s", so->dt > 0 ? "the step given"
                                                                   : "their automatic steps");
        row(b, "engine", v);
        snprintf(v, sizeof v, "%ld drops, %ld unsettled (in no count)%s", sim->n, sim->unsettled,
                 sim->partial ? "; interrupted: partial" : "");
        row(b, "drops", v);
    } else {
        row(b, "drops", "none (QS and PQS only; -n N adds simulated drops)");
    }
    snprintf(v, sizeof v, "reading and static estimates %.3f s; drops %.3f s; in all, before "
             "drawing, %.3f s", run->seconds_static, run->seconds_sim, run->seconds_total);
    row(b, "timings (wall clock)", v);
    vbuf_put(b, "</table>\n<p>The command that made this report (rerun with the same input, "
                "options and seed, it gives the same numbers and pictures at any thread count; "
                "only the timings, and -j in this line, may differ):</p>\n<pre>");
    for (int i = 0; i < run->argc; i++) {
        if (i)
            vbuf_put(b, " ");
        shell_word(b, i == 0 ? "posedrop" : run->argv[i]);
    }
    vbuf_put(b, "</pre></section>\n");
}

static pd_status figure(vbuf *b, const char *id, const char *heading, const char *note,
                        pd_status (*fn)(const viz_input *, int, vbuf *, pd_diag *),
                        const viz_input *in, pd_diag *diag)
{
    vbuf_printf(b, "<section id=\"%s\"><h2>%s</h2>\n", id, heading);
    if (note)
        vbuf_printf(b, "<p class=\"note\">%s</p>\n", note);
    vbuf_put(b, "<figure>\n");
    pd_status st = fn(in, 0, b, diag);
    vbuf_put(b, "</figure></section>\n");
    return st;
}

pd_status viz_report(const viz_input *in, const viz_run *run, vbuf *b, pd_diag *diag)
{
    viz_entry *e;
    int n;
    pd_status st = viz_entries(in, &e, &n, diag);
    if (st != PD_OK)
        return st;
    vbuf_put(b, "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\"/>\n"
                "<meta name=\"viewport\" content=\"width=device-width, initial-scale=1\"/>\n"
                "<title>posedrop report: ");
    vbuf_escape(b, viz_base_name(in->name));
    vbuf_printf(b, "</title>\n<style>\n%s</style></head>\n<body>\n<h1>How ", style);
    vbuf_escape(b, viz_base_name(in->name));
    vbuf_printf(b, " comes to rest</h1>\n<p class=\"note\">posedrop %s: the probability of each "
                "stable pose of the part dropped on a flat floor, by the quasi-static (QS) and "
                "perturbed quasi-static (PQS) estimators%s.</p>\n", PD_VERSION_STRING,
                in->sim ? " and simulated drops" : "");
    /* The size up front: a file in millimetres read as metres shows here as
     * a part of tens of metres. */
    char size[64];
    static const char *const unit_names[] = {"metres", "centimetres", "millimetres", "inches"};
    length(size, sizeof size, in->part->size);
    vbuf_put(b, "<p class=\"size\">The part is <strong>");
    vbuf_escape(b, size);
    vbuf_printf(b, "</strong> across (its bounding box's diagonal), the file's numbers read as "
                   "%s.</p>\n", unit_names[run->units]);
    part_section(b, in, run);
    st = figure(b, "gallery", "Stable poses", NULL, viz_gallery, in, diag);
    if (st == PD_OK)
        st = figure(b, "chart", "Estimates side by side",
                    "One group of bars per pose; whiskers are 95% intervals.", viz_chart, in, diag);
    if (st == PD_OK)
        st = figure(b, "sphere", "Gauss-sphere map",
                    "Every direction gravity can have in the part's frame, coloured by the pose "
                    "that quasi-static motion from it ends in: each colour's share of the sphere "
                    "is that pose's QS probability.", viz_sphere, in, diag);
    if (st == PD_OK && in->sensitivity && in->sensitivity->nparams > 0) {
        vbuf_put(b, "<section id=\"sensitivity\"><h2>What each ranged parameter moves</h2>\n"
                    "<p class=\"note\">The scene's ranges are drawn anew for every drop, so the "
                    "estimates above are over the ranges. For each pose, the first-order "
                    "index is the share of its variance that one parameter explains alone "
                    "(docs/uncertainty.md).");
        if (in->scene && in->scene->initial == PD_INITIAL_STATIONARY)
            vbuf_printf(b, " A stationary run's sensitivity is that of its first drops: the "
                        "%ld settled drops started from uniform orientations.",
                        in->sensitivity->n);
        vbuf_put(b, "</p>\n");
        viz_sensitivity_words(b, in);
        vbuf_put(b, "<figure>\n");
        st = viz_sensitivity(in, 0, b, diag);
        vbuf_put(b, "</figure></section>\n");
    }
    if (st == PD_OK && in->sim && e[0].has_xc)
        crosscheck_section(b, in, e, n);
    if (st == PD_OK) {
        table_section(b, in, e, n);
        run_section(b, run, in->part, in->sim, in->scene, in->engines != NULL);
        vbuf_put(b, "</body></html>\n");
    }
    free(e);
    if (st == PD_OK && b->failed)
        st = pd_fail(diag, PD_ERR_NOMEM, "out of memory");
    return st;
}
