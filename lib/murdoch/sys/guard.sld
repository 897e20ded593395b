;;> \procedure{(start-heap-guard! bytes line)}
;;> Ends this process, writing \var{line} to standard error, once its
;;> heap passes \var{bytes}: the lab's heap-max, which Chibi's own ceiling
;;> does not hold (lib/murdoch/sys/heap-watch.c says why).  The body is
;;> lib/murdoch/sys/guard.stub and heap-watch.c, built into lib/murdoch/sys/guard.so by
;;> \scheme{make native}.

;;> \procedure{(heap-on-huge-pages!)}
;;> Moves the heap onto 2 MB pages now, as an address space forked from
;;> the lab's loader must (heap-watch.c says why); #f when the kernel
;;> cannot, which leaves the heap as it was.
(define-library (murdoch sys guard)
  (export start-heap-guard! heap-on-huge-pages!)
  (include-shared "guard"))
