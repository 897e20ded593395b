;;> \procedure{(set-process-name! name)}
;;> Names this process for ps and top (its kernel name, cut to 15 bytes):
;;> an address space is murdoch-UID, where it would be the loader's name.
;;>
;;> \procedure{(set-parent-death-signal! signal)}
;;> Has the kernel send \var{signal} to this process when the thread
;;> that forked it ends: an address space ends with the lab's loader.
;;> Both answer #f when the kernel refuses.
;;> The body is lib/murdoch/sys/process.stub, built by \scheme{make native}.
(define-library (murdoch sys process)
  (export set-process-name! set-parent-death-signal!)
  (include-shared "process"))
