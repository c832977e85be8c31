/* The host stages' threads: a calling thread's setting (what rsmooth_context_set_host_threads
 * gives a context's calls) caps the chunks and the threads rs_parallel_for starts, is the calling
 * thread's alone, and is restored after; RSMOOTH_HOST_THREADS and the cores are the default. */
#include "rsmooth_internal.h"
#include "test_util.h"

#include <pthread.h>
#include <string.h>

#define MAX_SEEN 64

typedef struct seen {
    pthread_mutex_t lock;
    pthread_t ids[MAX_SEEN];
    size_t count;
} seen;

static void record(void *ctx, size_t begin, size_t end, size_t chunk) {
    (void)begin;
    (void)end;
    (void)chunk;
    seen *s = ctx;
    pthread_mutex_lock(&s->lock);
    pthread_t self = pthread_self();
    bool known = false;
    for (size_t i = 0; i < s->count; i++)
        known = known || pthread_equal(s->ids[i], self);
    if (!known && s->count < MAX_SEEN)
        s->ids[s->count++] = self;
    pthread_mutex_unlock(&s->lock);
}

static size_t threads_used(size_t count) {
    seen s;
    memset(&s, 0, sizeof s);
    pthread_mutex_init(&s.lock, NULL);
    rs_parallel_for(count, 1, record, &s);
    pthread_mutex_destroy(&s.lock);
    return s.count;
}

static void *other_thread(void *arg) {
    size_t *out = arg;
    *out = rs_host_threads(); /* not the main thread's setting */
    return NULL;
}

int main(void) {
    size_t before = rs_set_call_threads(3);
    CHECK_EQ_INT(before, 0);
    CHECK_EQ_INT(rs_host_threads(), 3);
    CHECK_EQ_INT(rs_parallel_chunks(1000, 1), 3);
    CHECK_EQ_INT(threads_used(1000), 3);
    pthread_t t;
    size_t elsewhere = 0;
    CHECK(pthread_create(&t, NULL, other_thread, &elsewhere) == 0);
    pthread_join(t, NULL);
    rs_set_call_threads(1);
    CHECK_EQ_INT(threads_used(1000), 1);
    CHECK_EQ_INT(rs_set_call_threads(500), 1);
    CHECK_EQ_INT(rs_host_threads(), 64); /* capped */
    rs_set_call_threads(0);
    /* the default: RSMOOTH_HOST_THREADS, else the cores; the other thread saw the default too */
    CHECK_EQ_INT(elsewhere, rs_host_threads());
    printf("parallel: a call's setting caps its threads (3, 1, capped at 64), other threads keep "
           "the default (%zu)\n",
           rs_host_threads());
    return 0;
}
