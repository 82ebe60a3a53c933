// go_threads.h: a small fixed-size pthread pool that runs one indexed loop at a time.
//
// The calling thread takes part as worker 0, so a pool of 1 thread starts no thread at all.
// Items are handed out dynamically (atomic counter), so which worker runs an item varies from run
// to run: a task must write its results only to slots owned by the item and use only the scratch
// of the worker it is given. Then results are bitwise identical for any number of threads.
#ifndef GAITSIM_OPTIM_GO_THREADS_H_
#define GAITSIM_OPTIM_GO_THREADS_H_

typedef struct go_pool go_pool;

// one item of a parallel loop: worker in [0, nthreads), item in [0, nitems)
typedef void (*go_task_fn)(void* arg, int worker, int item);

// Create a pool of nthreads workers (1..64; worker 0 is the caller of go_pool_run).
// Returns 0 and sets *out, or -1 with a reason in err. Caller frees with go_pool_free.
int go_pool_create(go_pool** out, int nthreads, char* err, int errsz);

// Number of workers (including the calling thread).
int go_pool_nthreads(const go_pool* pool);

// Run fn(arg, worker, item) for item = 0..nitems-1 and return when all are done.
// Not reentrant: one loop at a time per pool.
void go_pool_run(go_pool* pool, int nitems, go_task_fn fn, void* arg);

// Stop and join the workers, free the pool. NULL is ignored.
void go_pool_free(go_pool* pool);

#endif  // GAITSIM_OPTIM_GO_THREADS_H_
