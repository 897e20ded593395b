;;> \procedure{(set-process-name! name)}
;;> Names this process for ps and top (its kernel name, cut to 15 bytes):
;;> an address space is murdoch-UID, where it would be the loader's name.
;;> The body is lib/murdoch/sys/process-name.stub, built by \scheme{make native}.
(define-library (murdoch sys process-name)
  (export set-process-name!)
  (include-shared "process-name"))
