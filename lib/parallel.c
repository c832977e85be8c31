/* Host loops on every core: the host stages (facet data, grid keys, packing, results) are
 * independent per element, and on a CPU device they would otherwise leave all but one core idle
 * while the kernels use them all. Static chunks, so every run splits the same way and results are
 * bit-identical; the calling thread works the first chunk. */
#define _DEFAULT_SOURCE /* sysconf's _SC_NPROCESSORS_ONLN */
#include "rsmooth_internal.h"

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
    const char *forced = getenv("RSMOOTH_HOST_THREADS");
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

void rs_parallel_for(size_t count, size_t min_per_chunk, rs_range_fn fn, void *ctx) {
    size_t chunks = rs_parallel_chunks(count, min_per_chunk);
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
