;;> define-record-type whose constructor makes no closure, for records
;;> made on a call's path.

(define-library (murdoch sys record)
  (export define-lean-record-type)
  (import (except (chibi) define-record-type)
          (rename (srfi 9) (define-record-type chibi-define-record-type)))
  (include "record.scm"))
