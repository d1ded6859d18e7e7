/* progress.c - errors and progress: the one error line "hfvis: <what>: <why>" (cli_error,
 * cli_status), the progress bar over several library calls, the --progress lines and the clock.
 * Owns: how a run reports to stderr. May call: the C library only. */

/* Print the one error line "hfvis: <what>: <why>" and return code. The progress bar is drawn
 * only on a terminal (cli_run_heights, cli_vf_build) and its line stays open while a run goes on,
 * so on a terminal the line is first erased (carriage return, then VT100 "erase to the end of the
 * line", which leaves an empty line as it is): an error never lands after an unfinished bar, and
 * no state is needed to know whether one is open. Every error line of the tool is printed here. */
static int cli_error(int code, const char *what, const char *fmt, ...)
{
    char why[512];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(why, sizeof why, fmt, ap);
    va_end(ap);
    if (cli_stderr_is_terminal()) fputs("\r\033[K", stderr);
    ex_error(what, why);
    return code;
}

/* A failed library call; for I/O errors the C library's reason is added when there is one. */
static int cli_status(const char *what, hfvis_status s, int saved_errno)
{
    if (s == HFVIS_ERR_IO && saved_errno != 0)
        return cli_error(CLI_EXIT_ERROR, what, "%s (%s)", hfvis_status_string(s),
                         strerror(saved_errno));
    return cli_error(CLI_EXIT_ERROR, what, "%s", hfvis_status_string(s));
}


/* A run's state before the run: no georeference, no window, the clock started now. */
static void cli_run_init(cli_run_state *run)
{
    memset(run, 0, sizeof *run);
    run->win.halo = -1;
    run->t0 = cli_now();
    run->line_pct = -1;
}

/* One library report (done of total) as the run's units now of all; the base moves on when a
 * call completes. */
static void cli_progress_advance(cli_progress_state *p, int done, int total, long long *now,
                                 long long *all)
{
    *all = p->total > 0 ? p->total : total;
    *now = p->total > 0 ? p->base + done : done;
    if (*now > *all) *now = *all;
    if (done >= total) p->base += total;
}

/* hfvis_progress_fn: "\r<command> [#####.....] done/total" on stderr. */
static void cli_progress(void *user, int done, int total)
{
    enum { BAR = 32 };
    cli_progress_state *p = (cli_progress_state *)user;
    long long all, now;
    char bar[BAR + 1];
    int i, fill;
    cli_progress_advance(p, done, total, &now, &all);
    fill = all > 0 ? (int)(now * BAR / all) : BAR;
    for (i = 0; i < BAR; i++) bar[i] = i < fill ? '#' : '.';
    bar[BAR] = '\0';
    fprintf(stderr, "\r%s [%s] %lld/%lld", p->label, bar, now, all);
    p->run->bar_open = now < all;
    if (!p->run->bar_open) fputc('\n', stderr);
    fflush(stderr);
}

/* At the end of a run that drew a bar: a bar that fell short of its total gets its newline
 * after a success (rc 0); after a failure the error line has erased it (cli_error). */
static void cli_progress_end(cli_run_state *run, int rc)
{
    if (run->bar_open && rc == 0) fputc('\n', stderr);
    run->bar_open = 0;
}

/* --max-memory's default: half of the physical memory where sysconf reports it, else 0 (none). */
static double cli_default_max_memory(void)
{
#if defined(CLI_HAVE_SIGACTION) && defined(_SC_PHYS_PAGES) && defined(_SC_PAGESIZE)
    long pages = sysconf(_SC_PHYS_PAGES), page = sysconf(_SC_PAGESIZE);
    if (pages > 0 && page > 0) return 0.5 * (double)pages * (double)page;
#endif
    return 0.0;
}

static int cli_stderr_is_terminal(void)
{
#ifdef CLI_HAVE_ISATTY
    return isatty(STDERR_FILENO);
#else
    return 0;
#endif
}

/* Seconds on a monotonic clock (wall clock where there is none). */
static double cli_now(void)
{
#if defined(CLOCK_MONOTONIC) && defined(CLI_HAVE_ISATTY)
    struct timespec ts;
    if (clock_gettime(CLOCK_MONOTONIC, &ts) == 0) return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
#endif
    return (double)time(NULL);
}

/* hfvis_progress_fn of --progress: plain lines "hfvis CMD: P% (done/total), T s elapsed, ETA E s"
 * on stderr, one per 5% (or per 30 s), for logs and job schedulers. */
static void cli_progress_line(void *user, int done, int total)
{
    cli_progress_state *p = (cli_progress_state *)user;
    long long all, now;
    double t = cli_now() - p->run->t0;
    int pct;
    cli_progress_advance(p, done, total, &now, &all);
    pct = all > 0 ? (int)(now * 100 / all) : 100;
    if (pct >= p->run->line_pct + 5 || now == all || t - p->run->line_last >= 30.0) {
        if (now >= all)
            fprintf(stderr, "hfvis %s: 100%% (%lld/%lld), %.1f s\n", p->label, now, all, t);
        else if (now > 0)
            fprintf(stderr, "hfvis %s: %d%% (%lld/%lld), %.0f s elapsed, ETA %.0f s\n", p->label, pct,
                    now, all, t, t * (double)(all - now) / (double)now);
        else
            fprintf(stderr, "hfvis %s: 0%% (0/%lld), %.0f s elapsed\n", p->label, all, t);
        fflush(stderr);
        p->run->line_pct = pct;
        p->run->line_last = t;
    }
}
