;;; The libraries as layers: each imports only from its own layer and
;;; those below, and no import goes round in a cycle.  The order of the
;;; layers is written here, once; README's "The shape" follows it.
(import (scheme base) (scheme read) (scheme file) (scheme write)
        (srfi 1) (chibi test)
        (only (chibi filesystem) directory-files)
        (murdoch testing))

;; Bottom to top.
(define layers
  '((process (murdoch scheduler) (murdoch guard) (murdoch process-name) (murdoch log)
             (murdoch wait))
    (wire (murdoch remote-error) (murdoch netstring) (murdoch hmac)
          (murdoch multicast) (murdoch connect) (murdoch frame))
    (lab (murdoch lab))
    (values (murdoch sendable) (murdoch abandon) (murdoch sandbox))
    (robot (murdoch trip-client))
    (aspace (murdoch aspace))
    (call (murdoch connection) (murdoch worker) (murdoch call))
    (group (murdoch group))
    (serve (murdoch serve))
    (proxy (murdoch proxy))
    (delivery (murdoch delivery))
    (remote (murdoch remote))
    (messaging (murdoch pubsub))
    (monitors (murdoch monitor))
    (task-parts (murdoch assign) (murdoch progress) (murdoch metric) (murdoch takers))
    (team (murdoch team))
    (tasks (murdoch pose-task) (murdoch component))
    (life-cycle (murdoch task) (murdoch status))
    (interface (murdoch))
    (commands (murdoch hints) (murdoch command) (murdoch launch) (murdoch view))))

(define (layer-of name)
  (list-index (lambda (layer) (member name (cdr layer))) layers))

;; The define-library form of file.
(define (library-form file)
  (call-with-input-file file read))

;; The library names an import set names, inside only, except, rename and
;; prefix.
(define (import-set-library set)
  (if (memq (car set) '(only except rename prefix))
      (import-set-library (cadr set))
      set))

(define (imports form)
  (append-map (lambda (decl)
                (if (and (pair? decl) (eq? (car decl) 'import))
                    (map import-set-library (cdr decl))
                    '()))
              (cddr form)))

(define (ours? name) (and (pair? name) (eq? (car name) 'murdoch)))

(define library-files
  (cons (tool-path "murdoch.sld")
        (map (lambda (f) (tool-path (string-append "lib/murdoch/" f)))
             (filter (lambda (f) (text-contains? f ".sld"))
                     (directory-files (tool-path "lib/murdoch"))))))

;; (name . imports of ours), for every library.
(define graph
  (map (lambda (file)
         (let ((form (library-form file)))
           (cons (cadr form) (filter ours? (imports form)))))
       library-files))

;; The libraries on a path of imports from name back to name, or #f.
(define (cycle-from name)
  (let walk ((here name) (path '()))
    (cond ((and (pair? path) (equal? here name)) (reverse (cons here path)))
          ((member here path) #f)
          (else (any (lambda (next) (walk next (cons here path)))
                     (cond ((assoc here graph) => cdr) (else '())))))))

(test-begin "layers")

(test "every library has a layer" '()
  (remove layer-of (map car graph)))

(test "no library imports from a layer above its own" '()
  (append-map (lambda (entry)
                (filter-map (lambda (import)
                              (and (layer-of import) (layer-of (car entry))
                                   (> (layer-of import) (layer-of (car entry)))
                                   (list (car entry) 'imports import)))
                            (cdr entry)))
              graph))

(test "no imports go round in a cycle" '()
  (filter-map cycle-from (map car graph)))

(test-end)
(test-exit)
