/* Host loops on every core: the host stages (facet data, grid keys, packing, results) are
 * independent per element, and on a CPU device they would otherwise leave all but one core idle
 * while the kernels use them all. Static chunks, so every run splits the same way and results are
 * bit-identical; the calling thread works the first chunk, worker c - 1 chunk c.
 *
 * The workers are made once, when a loop first needs them, and wait on a condition variable
 * between loops (a run calls rs_parallel_for some twenty times; creating and joining threads at
 * each cost more than the short loops themselves). One caller at a time has the pool: a second
 * thread calling meanwhile (another context), or a loop called from inside a chunk, starts threads
 * of its own for that call, as every call did before. A forked child starts with no workers, and
 * the workers are stopped when the library is unloaded. */
#define _DEFAULT_SOURCE /* sysconf's _SC_NPROCESSORS_ONLN */
#include "core/environment.h"
#include "core/rsmooth_internal.h"

#include <pthread.h>
#include <stdlib.h>
#include <unistd.h>

#define MAX_THREADS 64

/* Per calling thread, so that two contexts with their own settings may run at once. */
static _Thread_local size_t call_threads;

size_t rs_set_call_threads(size_t threads) {
    size_t before = call_threads;
    call_threads = threads;
    return before;
}

size_t rs_host_threads(void) {
    if (call_threads)
        return call_threads > MAX_THREADS ? MAX_THREADS : call_threads;
    const char *forced = rs_environment_now(RS_ENV_HOST_THREADS);
    long n = forced ? atol(forced) : sysconf(_SC_NPROCESSORS_ONLN);
    return n < 1 ? 1 : n > MAX_THREADS ? MAX_THREADS : (size_t)n;
}

size_t rs_parallel_chunks(size_t count, size_t min_per_chunk) {
    size_t chunks = rs_host_threads();
    if (min_per_chunk < 1)
        min_per_chunk = 1;
    if (count / min_per_chunk < chunks)
        chunks = count / min_per_chunk;
    return chunks < 1 ? 1 : chunks;
}

typedef struct chunk_job {
    rs_range_fn fn;
    void *ctx;
    size_t begin, end, chunk;
} chunk_job;

static void *run_chunk(void *arg) {
    chunk_job *job = arg;
    job->fn(job->ctx, job->begin, job->end, job->chunk);
    return NULL;
}

/* For a call that cannot have the pool: a thread per chunk, joined before it returns. */
static void spawn_for(size_t count, size_t chunks, rs_range_fn fn, void *ctx) {
    chunk_job jobs[MAX_THREADS];
    pthread_t threads[MAX_THREADS];
    bool started[MAX_THREADS] = {false};
    for (size_t c = 0; c < chunks; c++)
        jobs[c] = (chunk_job){fn, ctx, count * c / chunks, count * (c + 1) / chunks, c};
    for (size_t c = 1; c < chunks; c++)
        started[c] = pthread_create(&threads[c], NULL, run_chunk, &jobs[c]) == 0;
    run_chunk(&jobs[0]);
    for (size_t c = 1; c < chunks; c++) {
        if (started[c])
            pthread_join(threads[c], NULL);
        else
            run_chunk(&jobs[c]); /* no thread to be had: do it here */
    }
}

typedef struct worker {
    size_t index;  /* works chunk index + 1 */
    uint64_t seen; /* the last loop it looked at */
    pthread_t thread;
} worker;

/* Everything below `lock` is read and written under it, but for the job's fn, ctx, count and
 * chunks, which only the pool's holder writes, before it publishes a loop (generation++). */
static struct {
    pthread_mutex_t lock;
    pthread_cond_t wake; /* workers: a new loop or the end */
    pthread_cond_t done; /* the holder: pending reached 0 */
    bool busy;           /* a caller has the pool */
    bool stop;
    uint64_t generation; /* loops published */
    size_t worker_count;
    worker workers[MAX_THREADS - 1];
    rs_range_fn fn;
    void *ctx;
    size_t count, chunks, pending;
} pool = {.lock = PTHREAD_MUTEX_INITIALIZER,
          .wake = PTHREAD_COND_INITIALIZER,
          .done = PTHREAD_COND_INITIALIZER};

static pthread_once_t pool_once = PTHREAD_ONCE_INIT;
static _Thread_local bool in_worker;

/* The child of a fork has none of the parent's workers, and the lock may have been held by a
 * thread that is not there: it starts over with an empty pool. */
static void pool_after_fork(void) {
    pthread_mutex_init(&pool.lock, NULL);
    pthread_cond_init(&pool.wake, NULL);
    pthread_cond_init(&pool.done, NULL);
    pool.busy = pool.stop = false;
    pool.generation = 0;
    pool.worker_count = 0;
    pool.pending = 0;
}

static void pool_register(void) {
    pthread_atfork(NULL, NULL, pool_after_fork);
}

static void *worker_main(void *arg) {
    worker *w = arg;
    in_worker = true;
    pthread_mutex_lock(&pool.lock);
    for (;;) {
        while (pool.generation == w->seen && !pool.stop)
            pthread_cond_wait(&pool.wake, &pool.lock);
        if (pool.stop)
            break;
        w->seen = pool.generation;
        size_t c = w->index + 1;
        if (c >= pool.chunks)
            continue;
        pthread_mutex_unlock(&pool.lock);
        pool.fn(pool.ctx, pool.count * c / pool.chunks, pool.count * (c + 1) / pool.chunks, c);
        pthread_mutex_lock(&pool.lock);
        if (--pool.pending == 0)
            pthread_cond_signal(&pool.done);
    }
    pthread_mutex_unlock(&pool.lock);
    return NULL;
}

/* Stops and joins the workers when the library goes (exit, or dlclose of the shared library),
 * unless a loop is running then. Meanwhile the pool is busy: a loop called from another thread
 * starts threads of its own. */
__attribute__((destructor)) static void pool_stop(void) {
    pthread_mutex_lock(&pool.lock);
    if (pool.busy || pool.worker_count == 0) {
        pthread_mutex_unlock(&pool.lock);
        return;
    }
    pool.busy = pool.stop = true;
    pthread_cond_broadcast(&pool.wake);
    size_t n = pool.worker_count;
    pool.worker_count = 0;
    pthread_mutex_unlock(&pool.lock);
    for (size_t i = 0; i < n; i++)
        pthread_join(pool.workers[i].thread, NULL);
    pthread_mutex_lock(&pool.lock);
    pool.busy = pool.stop = false;
    pthread_mutex_unlock(&pool.lock);
}

void rs_parallel_for(size_t count, size_t min_per_chunk, rs_range_fn fn, void *ctx) {
    size_t chunks = rs_parallel_chunks(count, min_per_chunk);
    if (chunks == 1) {
        fn(ctx, 0, count, 0);
        return;
    }
    pthread_once(&pool_once, pool_register);
    pthread_mutex_lock(&pool.lock);
    if (pool.busy || in_worker) {
        pthread_mutex_unlock(&pool.lock);
        spawn_for(count, chunks, fn, ctx);
        return;
    }
    pool.busy = true;
    while (pool.worker_count < chunks - 1) {
        worker *w = &pool.workers[pool.worker_count];
        w->index = pool.worker_count;
        w->seen = pool.generation;
        if (pthread_create(&w->thread, NULL, worker_main, w) != 0)
            break; /* no more threads to be had: the caller works the rest */
        pool.worker_count++;
    }
    size_t helped = pool.worker_count < chunks - 1 ? pool.worker_count : chunks - 1;
    pool.fn = fn;
    pool.ctx = ctx;
    pool.count = count;
    pool.chunks = chunks;
    pool.pending = helped;
    pool.generation++;
    pthread_cond_broadcast(&pool.wake);
    pthread_mutex_unlock(&pool.lock);
    fn(ctx, 0, count / chunks, 0);
    for (size_t c = helped + 1; c < chunks; c++)
        fn(ctx, count * c / chunks, count * (c + 1) / chunks, c);
    pthread_mutex_lock(&pool.lock);
    while (pool.pending > 0)
        pthread_cond_wait(&pool.done, &pool.lock);
    pool.busy = false;
    pthread_mutex_unlock(&pool.lock);
}
