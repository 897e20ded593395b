;;> \procedure{(start-heap-guard! bytes line)}
;;> Ends this process, writing \var{line} to standard error, once its heap
;;> passes \var{bytes}, the lab's heap-max (heap-watch.c says why Chibi's
;;> own ceiling does not do).  Body: guard.stub and heap-watch.c.
;;> \procedure{(heap-on-huge-pages!)}
;;> Moves the heap onto 2 MB pages, as an address space forked from the
;;> lab's loader must (heap-watch.c); #f when the kernel cannot.
;;> cannot, which leaves the heap as it was.
(define-library (murdoch sys guard)
  (export start-heap-guard! heap-on-huge-pages!)
  (include-shared "guard"))
