// go_threads.c: fixed-size pthread pool, one indexed loop at a time (see go_threads.h).
#include "optim/go_threads.h"

#include <pthread.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>

#define GO_POOL_MAX_THREADS 64

struct go_pool {
  int nthreads;                 // workers including the caller
  pthread_t tid[GO_POOL_MAX_THREADS];
  pthread_mutex_t mu;
  pthread_cond_t cv_start;      // signalled when a new loop (generation) starts or on shutdown
  pthread_cond_t cv_done;       // signalled when a worker finishes its share of a loop
  long generation;              // loop counter, protected by mu
  int shutdown;                 // 1: workers exit
  int active;                   // helper threads still working on the current loop
  go_task_fn fn;                // current task
  void* arg;                    // current task argument
  int nitems;                   // items in the current loop
  atomic_int next;              // next item to hand out
};

typedef struct {
  go_pool* pool;
  int worker;
} go_worker_arg;

// take items until none are left
static void drain(go_pool* p, int worker) {
  for (;;) {
    int i = atomic_fetch_add(&p->next, 1);
    if (i >= p->nitems) return;
    p->fn(p->arg, worker, i);
  }
}

// helper thread body: wait for a generation, drain, report
static void* worker_main(void* a) {
  go_pool* p = ((go_worker_arg*)a)->pool;
  int worker = ((go_worker_arg*)a)->worker;
  free(a);
  long seen = 0;
  for (;;) {
    pthread_mutex_lock(&p->mu);
    while (!p->shutdown && p->generation == seen) pthread_cond_wait(&p->cv_start, &p->mu);
    if (p->shutdown) {
      pthread_mutex_unlock(&p->mu);
      return NULL;
    }
    seen = p->generation;
    pthread_mutex_unlock(&p->mu);

    drain(p, worker);

    pthread_mutex_lock(&p->mu);
    if (--p->active == 0) pthread_cond_signal(&p->cv_done);
    pthread_mutex_unlock(&p->mu);
  }
}

int go_pool_create(go_pool** out, int nthreads, char* err, int errsz) {
  *out = NULL;
  if (nthreads < 1 || nthreads > GO_POOL_MAX_THREADS) {
    snprintf(err, (size_t)errsz, "thread pool: %d threads requested (1..%d)", nthreads,
             GO_POOL_MAX_THREADS);
    return -1;
  }
  go_pool* p = calloc(1, sizeof(go_pool));
  if (!p) {
    snprintf(err, (size_t)errsz, "thread pool: out of memory");
    return -1;
  }
  p->nthreads = 1;
  atomic_init(&p->next, 0);
  pthread_mutex_init(&p->mu, NULL);
  pthread_cond_init(&p->cv_start, NULL);
  pthread_cond_init(&p->cv_done, NULL);
  for (int w = 1; w < nthreads; w++) {
    go_worker_arg* a = malloc(sizeof(go_worker_arg));
    if (!a) {
      go_pool_free(p);
      snprintf(err, (size_t)errsz, "thread pool: out of memory");
      return -1;
    }
    a->pool = p;
    a->worker = w;
    if (pthread_create(&p->tid[w], NULL, worker_main, a) != 0) {
      free(a);
      go_pool_free(p);
      snprintf(err, (size_t)errsz, "thread pool: pthread_create failed for worker %d", w);
      return -1;
    }
    p->nthreads = w + 1;
  }
  *out = p;
  return 0;
}

int go_pool_nthreads(const go_pool* pool) { return pool->nthreads; }

void go_pool_run(go_pool* p, int nitems, go_task_fn fn, void* arg) {
  if (nitems <= 0) return;
  // serial: no synchronisation at all
  if (p->nthreads == 1 || nitems == 1) {
    for (int i = 0; i < nitems; i++) fn(arg, 0, i);
    return;
  }
  pthread_mutex_lock(&p->mu);
  p->fn = fn;
  p->arg = arg;
  p->nitems = nitems;
  atomic_store(&p->next, 0);
  p->active = p->nthreads - 1;
  p->generation++;
  pthread_cond_broadcast(&p->cv_start);
  pthread_mutex_unlock(&p->mu);

  drain(p, 0);

  pthread_mutex_lock(&p->mu);
  while (p->active > 0) pthread_cond_wait(&p->cv_done, &p->mu);
  pthread_mutex_unlock(&p->mu);
}

void go_pool_free(go_pool* p) {
  if (!p) return;
  pthread_mutex_lock(&p->mu);
  p->shutdown = 1;
  pthread_cond_broadcast(&p->cv_start);
  pthread_mutex_unlock(&p->mu);
  for (int w = 1; w < p->nthreads; w++) pthread_join(p->tid[w], NULL);
  pthread_mutex_destroy(&p->mu);
  pthread_cond_destroy(&p->cv_start);
  pthread_cond_destroy(&p->cv_done);
  free(p);
}
