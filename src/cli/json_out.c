/* json_out.c: --format json, one document: the rows of the CSV (the same
 * columns, same digits) and the run's metadata, for programs that would
 * otherwise parse stderr. */
#include <errno.h>
#include <inttypes.h>
#include <string.h>
#include "cli/cli.h"

static void string(FILE *out, const char *s)
{
    fputc('"', out);
    for (; *s; s++) {
        unsigned char c = (unsigned char)*s;
        if (c == '"' || c == '\\')
            fprintf(out, "\\%c", c);
        else if (c < 0x20)
            fprintf(out, "\\u%04x", c);
        else
            fputc(c, out);
    }
    fputc('"', out);
}

static pd_vec3 add3(pd_vec3 a, pd_vec3 b)
{
    return (pd_vec3){a.x + b.x, a.y + b.y, a.z + b.z};
}

static void vec(FILE *out, pd_vec3 v)
{
    fprintf(out, "[%.17g, %.17g, %.17g]", v.x, v.y, v.z);
}

static const char *name_of(int i, const char *const *names) { return names[i]; }

static void part_json(FILE *out, const cli_args *a, const pd_part *part)
{
    static const char *const units[] = {"m", "cm", "mm", "in"};
    char sha[65];
    fprintf(out, "  \"part\": {\n    \"file\": ");
    string(out, a->path);
    fprintf(out, ",\n    \"sha256\": ");
    if (sha256_file(a->path, sha))
        string(out, sha);
    else
        fprintf(out, "null");
    fprintf(out, ",\n    \"units\": \"%s\",\n    \"vertices\": %d,\n    \"triangles\": %d,\n"
            "    \"closed\": %s,\n    \"size_m\": %.17g,\n    \"centre_of_mass_m\": ",
            name_of(a->read.units, units), part->mesh->nverts, part->mesh->ntris,
            part->closed ? "true" : "false", part->size);
    /* In the file's frame, as --com takes it: the part's own frame is moved
     * to part->origin. */
    vec(out, add3(part->com, part->origin));
    fprintf(out, ",\n    \"centre_of_mass_given\": %s,\n    \"mass\": ",
            a->part.com_given ? "true" : "false");
    if (part->mass_known) {
        const double (*I)[3] = part->mass.inertia;
        fprintf(out, "{\"volume_m3\": %.17g, \"centre_of_mass_m\": ", part->mass.volume);
        vec(out, add3(part->mass.com, part->origin));
        fprintf(out, ", \"inertia_per_density_m5\": [[%.17g, %.17g, %.17g], [%.17g, %.17g, %.17g], "
                "[%.17g, %.17g, %.17g]]}", I[0][0], I[0][1], I[0][2], I[1][0], I[1][1], I[1][2],
                I[2][0], I[2][1], I[2][2]);
    } else {
        fprintf(out, "null");
    }
    fprintf(out, ",\n    \"hull\": {\"vertices\": %d, \"facets\": %d}\n  },\n",
            part->hull->nverts, part->hull->nfacets);
}

static void run_json(FILE *out, const cli_args *a, const pd_part *part, const pd_sim_result *sim,
                     const viz_engines *xe, double wall_s)
{
    static const char *const engines[] = {"impulse", "ode", "bullet"};
    static const char *const laws[] = {"poisson", "energetic"};
    static const char *const initials[] = {"uniform", "bootstrap", "stationary"};
    const pd_scene *s = &a->scene;
    /* The duration the drops used: the automatic one is the part's. */
    int auto_time = s->contact_time == PD_CONTACT_TIME_AUTO;
    double contact_time =
        auto_time ? pd_contact_time_auto(pd_contact_time_auto_size(part)) : s->contact_time;
    fprintf(out, "  \"posedrop\": {\"version\": \"%s\", \"command_line\": [", pd_version());
    for (int i = 0; i < a->argc; i++) {
        fprintf(out, i ? ", " : "");
        string(out, a->argv[i]);
    }
    fprintf(out, "], \"merged_shards\": %s, \"wall_s\": %.6f, \"cpu_s\": %.6f},\n",
            a->merge ? "true" : "false", wall_s, cli_cpu_seconds());
    fprintf(out, "  \"scene\": {\"height_m\": %.17g, \"belt_speed_m_s\": %.17g, \"mu\": %.17g, "
            "\"restitution\": %.17g, \"restitution_law\": \"%s\", \"vibration_rad\": %.17g, "
            "\"initial\": \"%s\", \"gravity_m_s2\": %.17g, \"contact_time_s\": %.17g, "
            "\"contact_time_auto\": %s},\n",
            s->height, s->belt_speed, s->mu, s->restitution, name_of(s->law, laws), s->vibration,
            name_of(s->initial, initials), s->gravity, contact_time, auto_time ? "true" : "false");
    /* Tumble and ranges only when set, so a run without them prints what it
     * always printed. */
    if (s->tumble != 0.0 || pd_scene_ranged(s)) {
        fprintf(out, "  \"scene_ranges\": {\"tumble_rad_s\": %.17g", s->tumble);
        static const char *const kinds[] = {"fixed", "uniform", "log_uniform"};
        for (int k = 0; k < PD_NPARAMS; k++) {
            const pd_dist *d = &s->range[k];
            if (d->kind != PD_DIST_FIXED)
                fprintf(out, ", \"%s\": {\"kind\": \"%s\", \"lo\": %.17g, \"hi\": %.17g, "
                        "\"multiple_of_auto\": %s}", pd_scene_param_name((pd_scene_param)k),
                        name_of(d->kind, kinds), d->lo, d->hi, d->auto_multiple ? "true" : "false");
        }
        fprintf(out, "},\n");
    }
    static const char *const topples[] = {"descent", "edge"};
    static const char *const compares[] = {"raw", "qs"};
    static const char *const bands[] = {"rect", "exact"};
    fprintf(out, "  \"static\": {\"topple\": \"%s\", \"epsilon_rad\": %.17g, \"pqs_compare\": \"%s\", "
            "\"pqs_band\": \"%s\"},\n", name_of(a->estimate.topple, topples), a->estimate.epsilon,
            name_of(a->estimate.compare, compares), name_of(a->estimate.band, bands));
    if (!sim) {
        fprintf(out, "  \"drops\": null,\n");
        return;
    }
    fprintf(out, "  \"drops\": {\"engine\": \"%s\", \"seed\": %" PRIu64 ", \"requested\": %ld, "
            "\"run\": %ld, \"unsettled\": %ld, \"partial\": %s, \"collisions\": %ld, "
            "\"energy_gain\": %ld, \"fallbacks\": %ld},\n",
            name_of(a->sim.engine, engines), a->sim.seed, a->sim.ndrops, sim->n, sim->unsettled,
            sim->partial ? "true" : "false", sim->collisions, sim->energy_gain, sim->fallbacks);
    if (!xe)
        return;
    /* --crosscheck: what each engine ran (null: stopped before it ran). */
    fprintf(out, "  \"crosscheck\": {");
    for (int k = 0; k < VIZ_ENGINES; k++) {
        const pd_sim_result *x = xe->sim[k];
        fprintf(out, "%s\"%s\": ", k ? ", " : "", engines[k]);
        if (x)
            fprintf(out, "{\"run\": %ld, \"unsettled\": %ld, \"partial\": %s}", x->n,
                    x->unsettled, x->partial ? "true" : "false");
        else
            fprintf(out, "null");
    }
    fprintf(out, "},\n");
}

/* The rows: one object per CSV row, keys the CSV's column names. */
static void rows_json(FILE *out, const pd_static_result *res, const pd_sim_result *sim,
                      const int *class_of, int nclasses, const viz_engines *xe)
{
    int nrows = class_of ? nclasses : res->nposes;
    fprintf(out, "  \"%s\": [\n", class_of ? "classes" : "poses");
    for (int r = 0; r < nrows; r++) {
        int first = -1;
        double qs = 0.0, pqs = 0.0;
        for (int i = 0; i < res->nposes; i++)
            if ((class_of ? class_of[i] : i) == r) {
                first = first < 0 ? i : first;
                qs += res->poses[i].p_qs;
                pqs += res->poses[i].p_pqs;
            }
        const pd_pose *p = &res->poses[first];
        fprintf(out, "    {\"pose\": %d, \"nx\": %.10g, \"ny\": %.10g, \"nz\": %.10g, \"area\": %.10g, "
                "\"height\": %.10g, \"p_qs\": %.10g, \"p_pqs\": %.10g", r + 1,
                cli_clean(p->normal.x), cli_clean(p->normal.y), cli_clean(p->normal.z), p->area,
                p->height, cli_clean(qs), cli_clean(pqs));
        if (sim)
            fprintf(out, ", \"n\": %ld, \"count\": %ld, \"p\": %.10g, \"ci_lo\": %.10g, "
                    "\"ci_hi\": %.10g, \"unsettled\": %ld, \"partial\": %d", sim->n, sim->count[r],
                    sim->p[r], sim->ci_lo[r], sim->ci_hi[r], sim->unsettled, sim->partial);
        if (xe) {
            /* As the CSV's columns; an engine that did not run is null. */
            static const char *const keys[] = {"p_impulse", "p_ode", "p_bullet"};
            for (int k = 0; k < VIZ_ENGINES; k++) {
                const pd_sim_result *x = xe->sim[k];
                if (x && x->n > 0)
                    fprintf(out, ", \"%s\": %.10g", keys[k], x->p[r]);
                else
                    fprintf(out, ", \"%s\": null", keys[k]);
            }
            viz_spread x = viz_engine_spread(xe, r);
            fprintf(out, ", \"p_engine_min\": %.10g, \"p_engine_max\": %.10g, "
                    "\"engines_disagree\": %d", x.lo, x.hi, x.apart);
        }
        if (class_of) {
            fprintf(out, ", \"members\": [");
            for (int i = 0, sep = 0; i < res->nposes; i++)
                if (class_of[i] == r) {
                    fprintf(out, sep ? ", %d" : "%d", i + 1);
                    sep = 1;
                }
            fprintf(out, "]");
        }
        fprintf(out, "}%s\n", r + 1 < nrows ? "," : "");
    }
    fprintf(out, "  ]\n");
}

void json_print(FILE *out, const cli_args *a, const pd_part *part, const pd_static_result *res,
                const pd_sim_result *sim, const int *class_of, int nclasses,
                const viz_engines *xe, double wall_s)
{
    fprintf(out, "{\n");
    run_json(out, a, part, sim, xe, wall_s);
    part_json(out, a, part);
    rows_json(out, res, sim, class_of, nclasses, xe);
    fprintf(out, "}\n");
}
