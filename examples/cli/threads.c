/* threads.c - --threads: the work of one run split over POSIX threads so that the output equals
 * the one-thread run's bit for bit (hfvis.h, "Threads"): the direction sums by quarter-turn group
 * added in order (lattice) or by bands of one direction at a time added in place (exact), the
 * horizon map by plane range (exact: costliest direction first), one sun by
 * bands across its direction, and openness --radius by row bands (receiver rectangles); the
 * tool's own per-row work around them (the shared normals, the exact-ray grid data, the finish of
 * the sums) by row bands
 * (cli_threaded_rows). The library
 * stays single-threaded; every call here is one of its reentrant calls on shared inputs. Without
 * POSIX threads (CLI_HAVE_THREADS 0) every split runs its units in order on the calling thread.
 * May call: progress.c (through the progress callbacks it wraps). */

#if defined(_POSIX_THREADS) && _POSIX_THREADS > 0 && !defined(CLI_NO_THREADS)
#include <pthread.h>
#define CLI_HAVE_THREADS 1
#else
#define CLI_HAVE_THREADS 0
#endif

#define CLI_THREADS_MAX 256 /* --threads' upper bound */

/* The online cores (sysconf), what --threads 0 asks for; 1 where unknown or without threads. */
static int cli_threads_online(void)
{
#if CLI_HAVE_THREADS && defined(_SC_NPROCESSORS_ONLN)
    long n = sysconf(_SC_NPROCESSORS_ONLN);
    return n < 1 ? 1 : n > CLI_THREADS_MAX ? CLI_THREADS_MAX : (int)n;
#else
    return 1;
#endif
}

/* The threads a run uses: --threads N, or by default the online cores as cli_check_cost capped
 * them to what --max-memory holds. */
static int cli_run_threads(const cli_args *a)
{
    return a->run && a->run->threads > 0 ? a->run->threads : a->threads;
}

/* One split run: units 0..units-1, taken in increasing order by the threads; each unit's result
 * goes to its thread's scratch and is then merged in unit order (merge is called for unit u only
 * after units 0..u-1 were merged, under the lock, so merges never overlap and keep the order). */
typedef struct cli_split cli_split;
typedef hfvis_status (*cli_unit_fn)(cli_split *sp, int unit, int thread, hfvis_sweep_options *o);
typedef void (*cli_merge_fn)(cli_split *sp, int unit, int thread);
struct cli_split {
    int units, threads;
    cli_unit_fn unit;
    cli_merge_fn merge;                  /* NULL: units write disjoint outputs, no merge */
    int phase;                           /* 0, or units per phase: a unit starts only after
                                            every unit of the phases before its own finished */
    void *ctx;                           /* the caller's */
    const hfvis_sweep_options *opts;     /* copied per unit; progress replaced */
    const hfvis_grid *grid;              /* an exact-ray run's grid: its exact-ray data
                                            (hfvis_exact_grid_rows by row bands) made once and shared by
                                            every unit (sweep options exact_grid), or NULL */
    int next, merged, finished;          /* next unit to take; units merged; units finished */
    hfvis_status status;                 /* the first failure (by unit order of discovery) */
    long long done, total;               /* progress: library calls' steps over all threads */
#if CLI_HAVE_THREADS
    pthread_mutex_t lock;
    pthread_cond_t turn;
#endif
};

static void cli_split_lock(cli_split *sp)
{
#if CLI_HAVE_THREADS
    pthread_mutex_lock(&sp->lock);
#else
    (void)sp;
#endif
}

static void cli_split_unlock(cli_split *sp)
{
#if CLI_HAVE_THREADS
    pthread_mutex_unlock(&sp->lock);
#else
    (void)sp;
#endif
}

/* The library's progress callback of one unit: one step of all threads' work, reported through
 * the run's own callback (bar or lines) under the lock, so the count covers every thread. */
typedef struct cli_unit_progress {
    cli_split *sp;
    int last; /* this unit's steps reported so far */
} cli_unit_progress;

static void cli_split_progress(void *user, int done, int total)
{
    cli_unit_progress *up = (cli_unit_progress *)user;
    cli_split *sp = up->sp;
    (void)total;
    cli_split_lock(sp);
    if (done > up->last) {
        sp->done += done - up->last;
        up->last = done;
        if (sp->opts->progress && sp->total > 0)
            sp->opts->progress(sp->opts->progress_user, (int)(sp->done < INT_MAX ? sp->done : INT_MAX),
                               (int)(sp->total < INT_MAX ? sp->total : INT_MAX));
    }
    cli_split_unlock(sp);
}

/* Large blocks (lattices, tangent planes, sums) are advised onto transparent huge pages where
 * the system offers them (madvise MADV_HUGEPAGE, Linux; elsewhere plain malloc): their first
 * touch then faults once per 2 MiB instead of once per 4 KiB page (about 11 us each on this
 * project's VMs), and the lattice gathers miss the TLB less. Measured in docs/performance.md,
 * Threads. cli_huge_alloc is the hfvis_allocator form, which every sweep command passes. */
#define CLI_HUGE_MIN ((size_t)4 << 20) /* smaller blocks stay on ordinary pages */
static void *cli_huge_advise(void *p, size_t size)
{
#if defined(MADV_HUGEPAGE) && defined(_SC_PAGESIZE)
    long page = sysconf(_SC_PAGESIZE);
    if (p && size >= CLI_HUGE_MIN && page > 0) { /* the whole pages inside the block */
        size_t mask = (size_t)page - 1, head = (size_t)(((uintptr_t)p + mask) & ~(uintptr_t)mask) - (size_t)(uintptr_t)p;
        if (head < size && ((size - head) & ~mask) > 0)
            (void)madvise((char *)p + head, (size - head) & ~mask, MADV_HUGEPAGE); /* a hint: failure is harmless */
    }
#else
    (void)size;
#endif
    return p;
}

static void *cli_huge_malloc(size_t size)
{
    return cli_huge_advise(malloc(size ? size : 1), size);
}

/* Zeroed, as calloc: a large block comes fresh from the system and is not touched here, so its
 * pages are first touched (and faulted) by whoever writes them, on their threads, not all on the
 * main thread before the run as a memset would. */
static void *cli_huge_calloc(size_t size)
{
    return cli_huge_advise(calloc(1, size ? size : 1), size);
}

static void *cli_huge_alloc(void *user, size_t size)
{
    (void)user;
    return cli_huge_malloc(size);
}

static void cli_huge_free(void *user, void *ptr)
{
    (void)user;
    free(ptr);
}

static const hfvis_allocator cli_huge_allocator = {cli_huge_alloc, cli_huge_free, NULL};

/* Each thread's allocator keeps the blocks the library frees and hands them back at its next
 * call of the same size: a unit's lattice and accumulator are page-faulted once per thread, not
 * once per unit (a first touch costs about 11 us per 4 KiB page on this project's VMs:
 * docs/performance.md). Blocks beyond CLI_KEEP_BLOCKS go straight to malloc/free. */
#define CLI_KEEP_BLOCKS 16
typedef struct cli_keep {
    void *ptr[CLI_KEEP_BLOCKS];
    size_t size[CLI_KEEP_BLOCKS];
    int used[CLI_KEEP_BLOCKS], n;
} cli_keep;

static void *cli_keep_alloc(void *user, size_t size)
{
    cli_keep *k = (cli_keep *)user;
    int i, best = -1;
    void *p;
    for (i = 0; i < k->n; i++) /* the smallest kept block that fits */
        if (!k->used[i] && k->size[i] >= size && (best < 0 || k->size[i] < k->size[best])) best = i;
    if (best >= 0) {
        k->used[best] = 1;
        return k->ptr[best];
    }
    p = cli_huge_malloc(size);
    if (p && k->n < CLI_KEEP_BLOCKS) {
        k->ptr[k->n] = p;
        k->size[k->n] = size;
        k->used[k->n++] = 1;
    }
    return p;
}

static void cli_keep_free(void *user, void *ptr)
{
    cli_keep *k = (cli_keep *)user;
    int i;
    for (i = 0; i < k->n; i++)
        if (k->ptr[i] == ptr) {
            k->used[i] = 0;
            return;
        }
    free(ptr);
}

static void cli_keep_release(cli_keep *k)
{
    int i;
    for (i = 0; i < k->n; i++) free(k->ptr[i]);
    k->n = 0;
}

typedef struct cli_worker {
    cli_split *sp;
    int thread;
} cli_worker;

static void *cli_split_worker(void *arg)
{
    cli_split *sp = ((cli_worker *)arg)->sp;
    const int thread = ((cli_worker *)arg)->thread;
    cli_keep keep;
    hfvis_allocator alloc;
    memset(&keep, 0, sizeof keep);
    alloc.alloc = cli_keep_alloc;
    alloc.free = cli_keep_free;
    alloc.user = &keep;
    for (;;) {
        hfvis_sweep_options o = *sp->opts;
        cli_unit_progress up;
        hfvis_status s;
        int u;
        cli_split_lock(sp);
        u = sp->status == HFVIS_OK && sp->next < sp->units ? sp->next++ : -1;
#if CLI_HAVE_THREADS
        while (u >= 0 && sp->phase && sp->finished < u / sp->phase * sp->phase && sp->status == HFVIS_OK)
            pthread_cond_wait(&sp->turn, &sp->lock); /* the phases before u's: all finished */
#endif
        if (sp->status != HFVIS_OK) u = -1;
        cli_split_unlock(sp);
        if (u < 0) break;
        up.sp = sp;
        up.last = 0;
        o.progress = cli_split_progress;
        o.progress_user = &up;
        o.alloc = &alloc;
        s = sp->unit(sp, u, thread, &o);
        cli_split_lock(sp);
        if (s != HFVIS_OK && sp->status == HFVIS_OK) sp->status = s;
#if CLI_HAVE_THREADS
        while (sp->merge && sp->merged != u && sp->status == HFVIS_OK) pthread_cond_wait(&sp->turn, &sp->lock);
#endif
        if (sp->merge && sp->status == HFVIS_OK) sp->merge(sp, u, thread);
        sp->merged = u + 1;
        sp->finished++;
#if CLI_HAVE_THREADS
        pthread_cond_broadcast(&sp->turn);
#endif
        cli_split_unlock(sp);
    }
    cli_keep_release(&keep);
    return NULL;
}

static hfvis_status cli_threaded_exact_grid(const hfvis_grid *grid, const hfvis_sweep_options *opts, int threads,
                                            double *out);

/* Run the split on sp->threads threads (the calling thread is one of them). */
static hfvis_status cli_split_run(cli_split *sp)
{
    cli_worker args[CLI_THREADS_MAX];
    const hfvis_sweep_options *given = sp->opts;
    hfvis_sweep_options shared;
    double *exact_data = NULL;
    int t;
    if (sp->grid && given && given->rays == HFVIS_RAYS_EXACT && !given->exact_grid && sp->units > 1) {
        /* hfvis_exact_grid_compute once, not in every unit's call; without the memory each
         * call makes its own (the same values) */
        exact_data = (double *)cli_huge_malloc(((size_t)sp->grid->width * (size_t)sp->grid->height + 1) * sizeof(double));
        if (exact_data && cli_threaded_exact_grid(sp->grid, given, sp->threads < sp->units ? sp->threads : sp->units,
                                                  exact_data) == HFVIS_OK) {
            shared = *given;
            shared.exact_grid = exact_data;
            sp->opts = &shared;
        }
    }
    sp->next = sp->merged = sp->finished = 0;
    sp->status = HFVIS_OK;
    sp->done = 0;
    if (sp->threads > sp->units) sp->threads = sp->units;
    if (sp->threads < 1) sp->threads = 1;
    for (t = 0; t < sp->threads; t++) {
        args[t].sp = sp;
        args[t].thread = t;
    }
#if CLI_HAVE_THREADS
    {
        pthread_t tid[CLI_THREADS_MAX];
        int started = 0;
        pthread_mutex_init(&sp->lock, NULL);
        pthread_cond_init(&sp->turn, NULL);
        for (t = 1; t < sp->threads; t++) /* a thread that cannot start leaves its share to others */
            if (pthread_create(&tid[started], NULL, cli_split_worker, &args[t]) == 0) started++;
        cli_split_worker(&args[0]);
        for (t = 0; t < started; t++) pthread_join(tid[t], NULL);
        pthread_cond_destroy(&sp->turn);
        pthread_mutex_destroy(&sp->lock);
    }
#else
    cli_split_worker(&args[0]);
#endif
    sp->opts = given;
    free(exact_data);
    return sp->status;
}

/* ---- per-row work of the tool itself (the shared normals, the finish of the sums): rows
 * [0, rows) in bands of at most CLI_ROWS_BAND rows, each band fn(ctx, y0, y1, thread) on one of
 * `threads` threads (one: in order on the calling thread); the bands must write disjoint outputs
 * (thread: an index < threads, for per-thread scratch of one band). Returns the first failing
 * band's status. */
#define CLI_ROWS_BAND 64 /* rows per unit: about 1 MB of a 4096-wide float plane */
typedef hfvis_status (*cli_rows_fn)(void *ctx, int y0, int y1, int thread);
typedef struct cli_rows_split {
    cli_rows_fn fn;
    void *ctx;
    int rows;
} cli_rows_split;

static hfvis_status cli_rows_unit(cli_split *sp, int u, int thread, hfvis_sweep_options *o)
{
    const cli_rows_split *j = (const cli_rows_split *)sp->ctx;
    const int y0 = u * CLI_ROWS_BAND, y1 = j->rows - y0 < CLI_ROWS_BAND ? j->rows : y0 + CLI_ROWS_BAND;
    (void)o;
    return j->fn(j->ctx, y0, y1, thread);
}

static hfvis_status cli_threaded_rows(int rows, int threads, cli_rows_fn fn, void *ctx)
{
    hfvis_sweep_options none = hfvis_sweep_options_default();
    cli_rows_split j;
    cli_split sp;
    if (rows <= CLI_ROWS_BAND) return fn(ctx, 0, rows, 0);
    memset(&sp, 0, sizeof sp);
    j.fn = fn;
    j.ctx = ctx;
    j.rows = rows;
    sp.units = (rows - 1) / CLI_ROWS_BAND + 1;
    sp.threads = threads;
    sp.unit = cli_rows_unit;
    sp.ctx = &j;
    sp.opts = &none;
    return cli_split_run(&sp);
}

/* ---- the raster writer's strips and tiles (ex_rio_write_options.parallel): calls fn(ctx, i)
 * for i in [0, n) over the run's threads (user: the thread count); the writer puts the chunks
 * in order, so the file's bytes do not depend on the split. */
typedef struct cli_for_split {
    int (*fn)(void *ctx, size_t i);
    void *ctx;
} cli_for_split;

static hfvis_status cli_for_unit(cli_split *sp, int u, int thread, hfvis_sweep_options *o)
{
    const cli_for_split *j = (const cli_for_split *)sp->ctx;
    (void)thread;
    (void)o;
    return j->fn(j->ctx, (size_t)u) == 0 ? HFVIS_OK : HFVIS_ERR_OUT_OF_MEMORY;
}

static int cli_parallel_for(void *user, size_t n, int (*fn)(void *ctx, size_t i), void *ctx)
{
    const int threads = *(const int *)user;
    hfvis_sweep_options none = hfvis_sweep_options_default();
    cli_for_split j;
    cli_split sp;
    size_t i;
    if (threads <= 1 || n <= 1 || n > (size_t)INT_MAX) {
        for (i = 0; i < n; i++)
            if (fn(ctx, i) != 0) return -1;
        return 0;
    }
    memset(&sp, 0, sizeof sp);
    j.fn = fn;
    j.ctx = ctx;
    sp.units = (int)n;
    sp.threads = threads;
    sp.unit = cli_for_unit;
    sp.ctx = &j;
    sp.opts = &none;
    return cli_split_run(&sp) == HFVIS_OK ? 0 : -1;
}

/* The exact-ray grid data of opts' calls (hfvis_exact_grid_compute's) over `threads` threads by
 * row bands (hfvis_exact_grid_rows): each band's pages are first touched by the thread that
 * computes it (at 4096^2 the 134 MB of twists took 0.39 s on one thread, most of it the kernel
 * zeroing fresh pages), and the class of the heights is the largest of the bands' classes: the
 * same doubles as the one call. The twists only where the calls read them (hfvis.h,
 * HFVIS_EXACT_TWIST_PLANE_CELLS): a large grid swept without the near field gets the class
 * alone (the rest of out is never touched, so never paged in). */
typedef struct cli_exact_grid_split {
    const hfvis_grid *grid;
    double *out;  /* NULL: the classes alone */
    int *cls;     /* per band of CLI_ROWS_BAND rows */
} cli_exact_grid_split;

static hfvis_status cli_exact_grid_band(void *ctx, int y0, int y1, int thread)
{
    const cli_exact_grid_split *j = (const cli_exact_grid_split *)ctx;
    (void)thread;
    return hfvis_exact_grid_rows(j->grid, y0, y1, j->out, &j->cls[y0 / CLI_ROWS_BAND]);
}

static hfvis_status cli_threaded_exact_grid(const hfvis_grid *grid, const hfvis_sweep_options *opts, int threads,
                                            double *out)
{
    cli_exact_grid_split j;
    const size_t n = (size_t)grid->width * (size_t)grid->height;
    const int bands = (grid->height - 1) / CLI_ROWS_BAND + 1;
    hfvis_status s;
    int b, cls = 0;
    j.grid = grid;
    j.out = n <= (size_t)HFVIS_EXACT_TWIST_PLANE_CELLS || opts->ray_near_cells > 0 ? out : NULL;
    if (!(j.cls = (int *)calloc((size_t)bands, sizeof(int)))) return HFVIS_ERR_OUT_OF_MEMORY;
    s = cli_threaded_rows(grid->height, threads, cli_exact_grid_band, &j);
    for (b = 0; b < bands; b++) cls = j.cls[b] > cls ? j.cls[b] : cls;
    out[n] = (double)cls;
    free(j.cls);
    return s;
}

/* The finish of a sum S of K directions as the single run computes it (hfvis.h, split runs):
 * the sky-view factor 1 - S/K, the sky light and environment light scale * S, where scale is
 * the product of the floats the run passes (sky * albedo, or albedo). */
static float cli_sum_finish(int cmd, int K, double scale, double S)
{
    if (cmd == CMD_SKYVIEW) return (float)(1.0 + (-1.0 / (double)K) * S);
    return (float)(0.0 + scale * S);
}

/* The band of the i-th unit of n bands across one direction, middle first: c, c+1, c-1, c+2,
 * ... with c = (n-1)/2. A direction's receivers per line fall off toward both edges of the grid
 * (a diagonal's corner lines hold a few cells), so the bands are then taken costliest first and
 * the last ones a thread takes are the cheapest: the threads finish the direction (or the sun)
 * close together. The order never changes a result (the bands write disjoint cells). */
static int cli_middle_out(int i, int n)
{
    const int c = (n - 1) / 2;
    return i % 2 ? c + (i + 1) / 2 : c - i / 2;
}

/* ---- the direction sums (skyview, sky, light). Lattice: one quarter-turn group (K % 4 == 0, in
 * sweep order) or one direction (K % 4 != 0) per unit, each into its thread's scratch, added in
 * unit order: the additions of the single run, one unit at a time (hfvis.h, split runs). Exact
 * rays: one phase per direction in index order, CLI_EXACT_BANDS_PER_THREAD bands across it per
 * thread, each band adding its receivers' terms in place to the one array of sums (hfvis.h,
 * hfvis_direction_sums, bands): no scratch sums, no merge, and no thread waits on a costlier
 * direction (an exact direction costs about |a| + |b| crossings per receiver, 1 to 9 at K = 16).
 * Either way the sums and their finish are the single run's bits. */
#define CLI_EXACT_BANDS_PER_THREAD 4 /* taken middle first (cli_middle_out); finer than 2 for
                                        bands of unequal content and a thread that loses its core
                                        (docs/performance.md, Threads) */
typedef struct cli_sums_split {
    const hfvis_grid *grid;
    int K, per, channels, bands;
    hfvis_sum_kind kind;
    const hfvis_env *env;
    const hfvis_env_options *eopts;
    size_t count;       /* values per sums array: width * height * channels */
    double *scratch;    /* threads * count */
    double *acc;        /* count: S */
} cli_sums_split;

static hfvis_status cli_sums_unit(cli_split *sp, int u, int thread, hfvis_sweep_options *o)
{
    cli_sums_split *j = (cli_sums_split *)sp->ctx;
    o->direction_order = o->rays == HFVIS_RAYS_EXACT ? HFVIS_DIRECTION_ORDER_INDEX : HFVIS_DIRECTION_ORDER_SWEEP;
    o->direction_begin = u * j->per;
    o->direction_end = u * j->per + j->per;
    return hfvis_direction_sums(j->grid, j->K, j->kind, j->env, j->eopts, o,
                                j->scratch + (size_t)thread * j->count);
}

static hfvis_status cli_band_sums_unit(cli_split *sp, int u, int thread, hfvis_sweep_options *o)
{
    cli_sums_split *j = (cli_sums_split *)sp->ctx;
    (void)thread;
    o->direction_order = HFVIS_DIRECTION_ORDER_INDEX;
    o->direction_begin = u / j->bands;
    o->direction_end = u / j->bands + 1;
    o->part_index = cli_middle_out(u % j->bands, j->bands);
    o->part_count = j->bands;
    return hfvis_direction_sums(j->grid, j->K, j->kind, j->env, j->eopts, o, j->acc);
}

static void cli_sums_merge(cli_split *sp, int u, int thread)
{
    cli_sums_split *j = (cli_sums_split *)sp->ctx;
    const double *part = j->scratch + (size_t)thread * j->count;
    size_t i;
    if (u == 0) memcpy(j->acc, part, j->count * sizeof(double));
    else for (i = 0; i < j->count; i++) j->acc[i] += part[i];
}

/* S of kind over all K directions into acc (count = width*height*channels doubles, interleaved
 * channels as hfvis_direction_sums, zeroed: cli_huge_calloc, so that its pages are first touched
 * by the exact bands on their threads and not by a memset here), on `threads` threads; the caller
 * finishes it. */
static hfvis_status cli_threaded_sums(const hfvis_grid *grid, int K, hfvis_sum_kind kind,
                                      const hfvis_env *env, const hfvis_env_options *eopts,
                                      const hfvis_sweep_options *opts, int threads, int channels,
                                      double *acc)
{
    cli_sums_split j;
    cli_split sp;
    hfvis_status s;
    memset(&j, 0, sizeof j);
    memset(&sp, 0, sizeof sp);
    j.grid = grid;
    j.K = K;
    j.kind = kind;
    j.env = env;
    j.eopts = eopts;
    j.channels = channels;
    j.per = opts->rays != HFVIS_RAYS_EXACT && K % 4 == 0 ? 4 : 1;
    j.count = (size_t)grid->width * (size_t)grid->height * (size_t)channels;
    j.acc = acc;
    sp.opts = opts;
    sp.grid = grid;
    sp.ctx = &j;
    if (opts->rays == HFVIS_RAYS_EXACT) { /* bands of one direction at a time, in place */
        j.bands = threads * CLI_EXACT_BANDS_PER_THREAD;
        sp.units = K * j.bands;
        sp.phase = j.bands;
        sp.threads = threads;
        sp.unit = cli_band_sums_unit;
        sp.total = sp.units;
        return cli_split_run(&sp);
    }
    sp.units = K / j.per;
    sp.threads = threads;
    if (sp.threads > sp.units) sp.threads = sp.units;
    j.scratch = (double *)cli_huge_malloc(j.count * (size_t)sp.threads * sizeof(double)); /* count <= 2^28*4 */
    if (!j.scratch) return HFVIS_ERR_OUT_OF_MEMORY;
    sp.unit = cli_sums_unit;
    sp.merge = cli_sums_merge;
    sp.total = K;
    s = cli_split_run(&sp);
    free(j.scratch);
    return s;
}

/* The grid's normals (hfvis_normals_compute) by row bands: each band computes them on the view
 * of its rows and the one row either side, which the library's stencil reaches (central
 * differences along x and y), into its thread's scratch, and copies its own rows: the whole
 * call's values. */
typedef struct cli_normals_rows {
    const hfvis_grid *grid;
    float *out;     /* width * height * 3 */
    float *scratch; /* threads * (CLI_ROWS_BAND + 2) * width * 3 */
} cli_normals_rows;

static hfvis_status cli_normals_band(void *ctx, int y0, int y1, int thread)
{
    const cli_normals_rows *j = (const cli_normals_rows *)ctx;
    const size_t row = (size_t)j->grid->width * 3;
    const int v0 = y0 > 0 ? y0 - 1 : 0, v1 = y1 < j->grid->height ? y1 + 1 : y1;
    float *tmp = j->scratch + (size_t)thread * (CLI_ROWS_BAND + 2) * row;
    hfvis_grid view = *j->grid;
    hfvis_status s;
    view.z += (ptrdiff_t)v0 * j->grid->stride;
    view.height = v1 - v0;
    s = hfvis_normals_compute(&view, tmp);
    if (s == HFVIS_OK)
        memcpy(j->out + (size_t)y0 * row, tmp + (size_t)(y0 - v0) * row, (size_t)(y1 - y0) * row * sizeof(float));
    return s;
}

/* The finish of the sums acc into out, by row bands (cli_sum_finish per value). */
typedef struct cli_finish_rows {
    int cmd, K;
    double scale;
    size_t row; /* values per row: width * channels */
    const double *acc;
    float *out;
} cli_finish_rows;

static hfvis_status cli_finish_band(void *ctx, int y0, int y1, int thread)
{
    const cli_finish_rows *j = (const cli_finish_rows *)ctx;
    size_t i;
    (void)thread;
    for (i = (size_t)y0 * j->row; i < (size_t)y1 * j->row; i++)
        j->out[i] = cli_sum_finish(j->cmd, j->K, j->scale, j->acc[i]);
    return HFVIS_OK;
}

/* skyview, sky or light (cmd) over all K directions on `threads` threads: S by
 * cli_threaded_sums, finished as the single run (scale: sky * albedo, or albedo, as the floats the
 * run passes), out[(y*width + x)*channels + c]. The lit commands compute the grid normals once
 * (by row bands) and give them to every unit (sweep options normals) instead of each call making
 * its own; the finish runs by row bands too. */
static hfvis_status cli_threaded_light(int cmd, const hfvis_grid *grid, int K, double scale,
                                       const hfvis_env *env, const hfvis_env_options *eopts,
                                       const hfvis_sweep_options *opts, int threads, int channels,
                                       float *out)
{
    const hfvis_sum_kind kind = cmd == CMD_SKYVIEW ? HFVIS_SUM_SKY_VIEW
                                : cmd == CMD_SKY ? HFVIS_SUM_SKY_LIGHT : HFVIS_SUM_ENV_LIGHT;
    const size_t n = (size_t)grid->width * (size_t)grid->height, count = n * (size_t)channels;
    double *acc = (double *)cli_huge_calloc(count * sizeof(double)); /* zeroed: cli_threaded_sums */
    float *nrm = NULL;
    hfvis_sweep_options o = *opts;
    hfvis_status s = HFVIS_OK;
    cli_finish_rows f;
    if (!acc) return HFVIS_ERR_OUT_OF_MEMORY;
    if (cmd != CMD_SKYVIEW && !o.normals) { /* the grid normals once, shared by every unit */
        const size_t band = ((size_t)CLI_ROWS_BAND + 2) * (size_t)grid->width * 3 * (size_t)threads;
        cli_normals_rows j;
        j.grid = grid;
        j.out = nrm = n <= SIZE_MAX / (3 * sizeof(float)) ? (float *)cli_huge_malloc(n * 3 * sizeof(float)) : NULL;
        j.scratch = (float *)malloc(band * sizeof(float)); /* width <= 2^28, threads <= 256 */
        s = nrm && j.scratch ? cli_threaded_rows(grid->height, threads, cli_normals_band, &j) : HFVIS_ERR_OUT_OF_MEMORY;
        free(j.scratch);
        o.normals = nrm;
    }
    if (s == HFVIS_OK) s = cli_threaded_sums(grid, K, kind, env, eopts, &o, threads, channels, acc);
    f.cmd = cmd, f.K = K, f.scale = scale, f.row = (size_t)grid->width * (size_t)channels, f.acc = acc, f.out = out;
    if (s == HFVIS_OK) s = cli_threaded_rows(grid->height, threads, cli_finish_band, &f);
    free(nrm);
    free(acc);
    return s;
}

/* ---- the horizon map: one quarter-turn group per unit (lattice, K % 4 == 0: its four planes in
 * sweep order, copied to their direction index) or one direction (written in place; exact rays:
 * the costliest directions first, so that the cheap ones fill the end and no thread idles long
 * while another finishes a costly one). */
typedef struct cli_map_split {
    const hfvis_grid *grid;
    int K, per;
    size_t n;           /* width * height */
    float *scratch;     /* threads * 4 planes (groups) */
    float *out;         /* K planes, direction index order */
    int *order;         /* NULL, or the direction of each unit (exact rays) */
    const unsigned char *need; /* NULL, or the directions to make (the others left as they are) */
} cli_map_split;

/* The cost of an exact direction's sweep: about |a| + |b| grid-line crossings per receiver for
 * the rational direction (a, b) the run uses at azimuth psi (hfvis_sweep_azimuths, psi =
 * atan2(b, a)): the smallest such pair with a major component up to CLI_EXACT_MAX_COMPONENT;
 * that bound if none is found (the order only balances the threads, it never changes a result). */
#define CLI_EXACT_MAX_COMPONENT 4096
static int cli_exact_cost(double psi)
{
    const double c = cos(psi), s = sin(psi), t = fabs(c) >= fabs(s) ? fabs(s / c) : fabs(c / s);
    int m;
    for (m = 1; m < CLI_EXACT_MAX_COMPONENT; m++) {
        const double minor = floor((double)m * t + 0.5);
        const double a = (fabs(c) >= fabs(s) ? (double)m : minor) * (c < 0.0 ? -1.0 : 1.0);
        const double b = (fabs(c) >= fabs(s) ? minor : (double)m) * (s < 0.0 ? -1.0 : 1.0);
        if (fabs(remainder(atan2(b, a) - psi, 2.0 * CLI_PI)) < 1e-9) return m + (int)minor;
    }
    return CLI_EXACT_MAX_COMPONENT;
}

typedef struct cli_cost_index {
    int cost, k;
} cli_cost_index;

static int cli_costlier_first(const void *x, const void *y)
{
    const cli_cost_index *p = (const cli_cost_index *)x, *q = (const cli_cost_index *)y;
    if (p->cost != q->cost) return p->cost > q->cost ? -1 : 1;
    return p->k < q->k ? -1 : p->k > q->k;
}

/* The K exact directions of opts ordered costliest first (ties: index order) into order[K];
 * HFVIS_OK, or the status of hfvis_sweep_azimuths / out of memory. */
static hfvis_status cli_exact_order(int K, const hfvis_sweep_options *opts, int *order)
{
    double *az = (double *)malloc((size_t)K * sizeof(double));
    cli_cost_index *ci = (cli_cost_index *)malloc((size_t)K * sizeof(cli_cost_index));
    hfvis_status s = az && ci ? hfvis_sweep_azimuths(K, opts, az, NULL) : HFVIS_ERR_OUT_OF_MEMORY;
    int k;
    for (k = 0; s == HFVIS_OK && k < K; k++) ci[k].cost = cli_exact_cost(az[k]), ci[k].k = k;
    if (s == HFVIS_OK) qsort(ci, (size_t)K, sizeof *ci, cli_costlier_first);
    for (k = 0; s == HFVIS_OK && k < K; k++) order[k] = ci[k].k;
    free(ci);
    free(az);
    return s;
}

static hfvis_status cli_map_unit(cli_split *sp, int u, int thread, hfvis_sweep_options *o)
{
    cli_map_split *j = (cli_map_split *)sp->ctx;
    hfvis_status s;
    int m, lo, hi;
    if (j->per == 1) { /* one direction, index order: its plane in place */
        const int k = j->order ? j->order[u] : u;
        if (j->need && !j->need[k]) return HFVIS_OK;
        o->direction_order = HFVIS_DIRECTION_ORDER_INDEX;
        o->direction_begin = k;
        o->direction_end = k + 1;
        return hfvis_horizon_map(j->grid, j->K, o, j->out + (size_t)k * j->n);
    }
    /* positions 4u..4u+3 (sweep order) are directions u + m K/4; with `need`, only the span of
       the needed m (the group's lattice is sampled once, its planes outside the span are neither
       swept nor gathered: the Colorado day needs 45 of 64) */
    for (lo = 0; lo < 4 && j->need && !j->need[u + lo * (j->K / 4)]; lo++) {}
    for (hi = 3; hi >= lo && j->need && !j->need[u + hi * (j->K / 4)]; hi--) {}
    if (lo > hi) return HFVIS_OK; /* a group none of whose directions is needed */
    o->direction_order = HFVIS_DIRECTION_ORDER_SWEEP;
    o->direction_begin = 4 * u + lo;
    o->direction_end = 4 * u + hi + 1;
    s = hfvis_horizon_map(j->grid, j->K, o, j->scratch + (size_t)thread * 4 * j->n);
    if (s == HFVIS_OK)
        for (m = lo; m <= hi; m++)
            memcpy(j->out + (size_t)(u + m * (j->K / 4)) * j->n,
                   j->scratch + ((size_t)thread * 4 + (size_t)(m - lo)) * j->n, j->n * sizeof(float));
    return s;
}

static hfvis_status cli_threaded_horizon_map(const hfvis_grid *grid, int K, const hfvis_sweep_options *opts,
                                             int threads, const unsigned char *need, float *out)
{
    cli_map_split j;
    cli_split sp;
    hfvis_status s;
    memset(&j, 0, sizeof j);
    memset(&sp, 0, sizeof sp);
    j.grid = grid;
    j.K = K;
    j.per = opts->rays != HFVIS_RAYS_EXACT && K % 4 == 0 ? 4 : 1;
    j.n = (size_t)grid->width * (size_t)grid->height;
    j.out = out;
    j.need = need;
    sp.units = K / j.per;
    sp.threads = threads > sp.units ? sp.units : threads;
    if (j.per == 4) {
        j.scratch = (float *)cli_huge_malloc(j.n * 4u * (size_t)sp.threads * sizeof(float));
        if (!j.scratch) return HFVIS_ERR_OUT_OF_MEMORY;
    } else if (opts->rays == HFVIS_RAYS_EXACT) {
        j.order = (int *)malloc((size_t)K * sizeof(int));
        s = j.order ? cli_exact_order(K, opts, j.order) : HFVIS_ERR_OUT_OF_MEMORY;
        if (s != HFVIS_OK) {
            free(j.order);
            return s;
        }
    }
    sp.unit = cli_map_unit;
    sp.ctx = &j;
    sp.opts = opts;
    sp.grid = grid;
    sp.total = K;
    s = cli_split_run(&sp);
    free(j.order);
    free(j.scratch);
    return s;
}

/* ---- one sun: bands across its direction (sweep options part_index/part_count), several per
 * thread and taken middle first (cli_middle_out) so that the short bands at the corners come
 * last and balance; every band writes its own cells of out. */
typedef struct cli_sun_split {
    const hfvis_grid *grid;
    double azimuth, elevation, radius;
    float *out;
    ptrdiff_t stride;
    int bands;
} cli_sun_split;

static hfvis_status cli_sun_unit(cli_split *sp, int u, int thread, hfvis_sweep_options *o)
{
    cli_sun_split *j = (cli_sun_split *)sp->ctx;
    (void)thread;
    o->part_index = cli_middle_out(u, j->bands);
    o->part_count = j->bands;
    return hfvis_sun_visibility(j->grid, j->azimuth, j->elevation, j->radius, o, j->out, j->stride);
}

#define CLI_SUN_BANDS_PER_THREAD 4 /* load balance against the bands' sampling margins */
static hfvis_status cli_threaded_sun(const hfvis_grid *grid, double azimuth, double elevation,
                                     double radius, const hfvis_sweep_options *opts, int threads,
                                     float *out, ptrdiff_t stride)
{
    cli_sun_split j;
    cli_split sp;
    if (threads <= 1) return hfvis_sun_visibility(grid, azimuth, elevation, radius, opts, out, stride);
    memset(&sp, 0, sizeof sp);
    j.grid = grid;
    j.azimuth = azimuth;
    j.elevation = elevation;
    j.radius = radius;
    j.out = out;
    j.stride = stride;
    j.bands = threads * CLI_SUN_BANDS_PER_THREAD;
    sp.units = j.bands;
    sp.threads = threads;
    sp.unit = cli_sun_unit;
    sp.ctx = &j;
    sp.opts = opts;
    sp.grid = grid;
    sp.total = j.bands;
    return cli_split_run(&sp);
}

/* ---- openness with a radius: row bands (receiver rectangles), each its own rows of out. */
typedef struct cli_open_split {
    const hfvis_grid *grid;
    int K, rows;
    const hfvis_openness_options *oo;
    float *out;
} cli_open_split;

static hfvis_status cli_open_unit(cli_split *sp, int u, int thread, hfvis_sweep_options *o)
{
    cli_open_split *j = (cli_open_split *)sp->ctx;
    (void)thread;
    o->receiver_x = 0;
    o->receiver_width = j->grid->width;
    o->receiver_y = u * j->rows;
    o->receiver_height = j->grid->height - o->receiver_y < j->rows ? j->grid->height - o->receiver_y : j->rows;
    return hfvis_openness(j->grid, j->K, j->oo, o, j->out, j->grid->width);
}

#define CLI_OPEN_ROWS 16 /* rows per unit */
static hfvis_status cli_threaded_openness(const hfvis_grid *grid, int K, const hfvis_openness_options *oo,
                                          const hfvis_sweep_options *opts, int threads, float *out)
{
    cli_open_split j;
    cli_split sp;
    if (threads <= 1 || oo->radius <= 0.0) return hfvis_openness(grid, K, oo, opts, out, grid->width);
    memset(&sp, 0, sizeof sp);
    j.grid = grid;
    j.K = K;
    j.oo = oo;
    j.out = out;
    j.rows = CLI_OPEN_ROWS;
    sp.units = (grid->height + j.rows - 1) / j.rows;
    sp.threads = threads;
    sp.unit = cli_open_unit;
    sp.ctx = &j;
    sp.opts = opts;
    sp.total = grid->height;
    return cli_split_run(&sp);
}
