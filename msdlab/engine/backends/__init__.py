"""The backends: what a step asks of the springs and the particles, and who computes it.

- `contract`: the methods every backend has (`SpringKernel`) and what they return;
- `choice`: which backend a simulation steps on (``kernel=``, ``MSDLAB_KERNEL``, and the
  readable numpy one while a debugger traces the program);
- `numpy`: the readable reference, the equations on whole arrays;
- `numba`: the same equations compiled into loops (the default), loaded only when chosen;
- `layout`: the body as the arrays every backend reads, laid out once per edit; `jacobian`:
  the sparsity of the springs' Jacobians, part of the layout;
- `process`: the settings of a process that steps bodies (its threads, its memory), made
  by msdlab's own processes, never by importing msdlab.
"""
