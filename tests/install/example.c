/* example.c: the library example of docs/library.md (and the README), as a
 * program: the static and the dynamic estimate of one part, as CSV.
 * tests/install/check-install.sh builds it against an installed posedrop
 * with plain pkg-config and checks its output against the posedrop command.
 *
 *   cc example.c $(pkg-config --cflags --libs posedrop) -o example
 *   ./example part.stl 2000 */
#include <stdio.h>
#include <stdlib.h>
#include <posedrop/posedrop.h>

int main(int argc, char **argv)
{
    if (argc != 3) {
        fprintf(stderr, "usage: %s PART DROPS\n", argv[0]);
        return 2;
    }
    pd_diag diag;
    pd_diag_init(&diag);
    pd_sim_options options;
    pd_sim_options_default(&options);
    options.ndrops = atol(argv[2]);

    pd_mesh *mesh = NULL;
    pd_part *part = NULL;
    pd_static_result *poses = NULL;
    pd_sim_result *drops = NULL;
    pd_status st = pd_mesh_read(argv[1], NULL, &mesh, &diag);
    if (st == PD_OK)
        st = pd_part_build(mesh, NULL, &part, &diag);
    if (st == PD_OK)
        st = pd_static_estimate(part, NULL, &poses, &diag);
    if (st == PD_OK)
        st = pd_sim_run(part, poses, NULL, &options, &drops, &diag);
    if (st != PD_OK) {
        fprintf(stderr, "%s: %s: %s\n", argv[1], pd_status_str(st), diag.message);
    } else {
        printf("# posedrop %s\n", pd_version());
        printf("pose,p_qs,p_pqs,count,p\n");
        for (int i = 0; i < poses->nposes; i++)
            printf("%d,%.10g,%.10g,%ld,%.10g\n", i + 1, poses->poses[i].p_qs,
                   poses->poses[i].p_pqs, drops->count[i], drops->p[i]);
    }
    pd_sim_result_free(drops);
    pd_static_result_free(poses);
    pd_part_free(part);
    pd_mesh_free(mesh);
    return st == PD_OK ? 0 : pd_status_is_input_error(st) ? 2 : 1;
}
