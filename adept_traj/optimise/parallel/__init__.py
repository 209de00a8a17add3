"""plan()'s work on worker processes beside it (each a process_pool.Worker): the polish
worker and the front members' certificates, early and late."""
