/* settings.h -- the settings of a run: the keys of a scene's [run] table (scene/keys.c, the
 * rows of table "run"), a struct of their own.
 *
 * A scene holds them as read from its file (swim_scene.run, its --set overrides included), and
 * nothing writes them there after. A command resolves the settings of its run once: the scene's
 * [run], then its own options (swim run's --rtol, a sweep's --integrator, ...), checked once
 * (swim_run_settings_check, scene/scene.h), and passes the resolved value to the run driver
 * (driver/run.h, swim_run_request.settings) and to the analyses; those read it, never the scene's.
 */
#ifndef SWIM_SCENE_SETTINGS_H
#define SWIM_SCENE_SETTINGS_H

typedef struct {
    double t_end, output_step, rtol, atol;
    char integrator[32];
    char stiff_fallback[32];          /* integrator to switch to when ABM detects stiffness ("cvode-bdf"
                                         unless the scene says "none": then "") */
    int project_initial;
    int projection;                   /* drift control after each step (ABM), default on */
    int origin_shift;                 /* abm with a barrier: shifted coordinates near the boundary of D
                                         (model/dynamics.h), default on */
    int energy_control;               /* abm: the local error of the energy balance joins the error
                                         test (swim_ode_options.invariant); 1, 0, or -1 when the scene
                                         does not say: on with a barrier, off without */
    double impact_depth;              /* abm with a barrier: a bounce predicted to turn below
                                         impact_depth |c_1|^2 is taken as an impact (model/bounce.h);
                                         0: never */
    int step_lookahead;               /* ABM step-size look-ahead p (swim_ode_options.lookahead); -1 = the integrator default */
    int jacobian_exact;               /* [run] jacobian: 1 "exact" (default: the kernel's exact
                                         Jacobian for integrators that use one), 0 "differences" */
    /* Found by the check on these settings, not a key: the first time in (0, t_end] where the
     * forcing law was found not finite (a sample, see swim_run_settings_check), or inf. */
    double forcing_finite_until;
} swim_run_settings;

#endif
